#!/usr/bin/env python3
"""A float32 GGX microfacet model speaking mfh's external protocol (version 2, or 1 with
--protocol 1; the protocol loop is mfh_protocol.py beside this file), vectorized with numpy:
every array of the model is float32 and every operation on it float32, as in a renderer whose
`Float` is 32 bits. mfh's float64 arrays are rounded to float32 on the way in and the float32
answers widened on the way out; the describe answer declares "precision": "f32". Run by mfh:

    mfh audit-external --cmd "python3 examples/external/ggx_f32_numpy.py" --profile ci \
        --against '{"family":"ggx","alpha":0.3}'

Capabilities: D, Lambda, normal sampling (sample_wm, pdf_wm) and visible-normal sampling
(sample_wm_visible, pdf_wm_visible). The formulas, for a unit vector w = (x, y, z):

    D(m)   = 1 / (pi ax ay (z^2 + (x/ax)^2 + (y/ay)^2)^2) for z > 0 (Walter et al. 2007 eq 33,
             multiplied out: no tan, no division by cos)
    Lambda = 1 / (2a (a + sqrt(a^2 + 1))), a = z / hypot(ax x, ay y) (Heitz 2014 for GGX, without
             its cancellation); below the horizon Lambda(w) = -1 - Lambda(-w)
    pdf_wm_visible = G1(wi) max(0, wi.m) D(m) / cos(theta_i), G1 = 1 / (1 + Lambda)
    sample_wm: phi = 2 pi u1, rho = (u2 / (1 - u2))^(1/2), slope (ax rho cos phi, ay rho sin phi),
             m = normalize(slope_x, slope_y, 1); pdf_wm = D(m) cos(theta_m) (Walter 2007 eq 35-36)
    sample_wm_visible: Heitz 2018 (JCGT 7(4)), as in ggx.py and cpp/ggx_float.cpp

Uniforms are rounded to float32 and kept below 1 (1 - 2^-24): a float64 u within 2^-25 of 1
would round to 1.0 and rho to infinity.

Options: --alpha A or --alpha-x AX --alpha-y AY (default 0.3), --protocol 1|2, and
--defect exponent, which plants a defect in the normal sampler's inversion: the exponent 1/2 of
rho = (u2 / (1 - u2))^(1/2) becomes 0.5 * 1.001 (0.1 % off). That 1/2 is the GGX slope
distribution's: the slope radius has the CDF F(rho) = rho^2 / (1 + rho^2) (P22 proportional to
(1 + rho^2)^-2), whose inverse is rho = (u / (1 - u))^(1/2). The sampled density then differs
from pdf_wm by about 0.1 % (more in the tails), which mfh's sampling.pdf_jacobian (pdf_wm
against the density of the map u -> m) sees; at the ci profile's 10^6 samples the chi-square
cannot resolve a distortion that small. Log to stderr only.
"""
import sys

import mfh_protocol
import numpy as np

F32 = np.float32
ONE_MINUS_EPSILON = F32(1.0) - F32(2.0**-24)
PI = F32(np.pi)


def _arguments():
    """(alpha_x, alpha_y, protocol, defect) from the command line."""
    args = sys.argv[1:]
    defect = "none"
    if "--defect" in args:
        k = args.index("--defect")
        defect = args[k + 1] if k + 1 < len(args) else ""
        del args[k:k + 2]
    if defect not in ("none", "exponent"):
        sys.exit("--defect is %r; known: none, exponent" % defect)
    ax, ay, protocol = mfh_protocol.options(args)
    return ax, ay, protocol, defect


AX64, AY64, PROTOCOL, DEFECT = _arguments()
AX, AY = F32(AX64), F32(AY64)
# The exponent of the slope radius inversion (1/2; planted 0.1 % off with --defect exponent).
RHO_EXPONENT = F32(0.5 * 1.001) if DEFECT == "exponent" else None


def f32(a):
    """A request array as float32 columns."""
    a = np.asarray(a, dtype=F32)
    return [a[:, k] for k in range(a.shape[1])]


def uniforms(u):
    u1, u2 = f32(u)
    return np.minimum(u1, ONE_MINUS_EPSILON), np.minimum(u2, ONE_MINUS_EPSILON)


def d_f32(x, y, z):
    t = z * z + (x / AX) ** 2 + (y / AY) ** 2
    with np.errstate(divide="ignore", over="ignore"):
        v = F32(1.0) / (PI * AX * AY * t * t)
    return np.where(z > F32(0.0), v, F32(0.0))


def lambda_f32(x, y, z):
    """Lambda for z >= 0 (float32 arrays)."""
    t = np.hypot(AX * x, AY * y)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a = z / t
        v = F32(1.0) / (F32(2.0) * a * (a + np.sqrt(a * a + F32(1.0))))
    return np.where(t == F32(0.0), F32(0.0), v)


def lambda_both(x, y, z):
    up = lambda_f32(np.abs(x), np.abs(y), np.abs(z))
    return np.where(z < F32(0.0), F32(-1.0) - up, up)


def d(m):
    return d_f32(*f32(m)).astype(np.float64)


def lam(w):
    return lambda_both(*f32(w)).astype(np.float64)


def normalize(x, y, z):
    inv = F32(1.0) / np.sqrt(x * x + y * y + z * z)
    return x * inv, y * inv, z * inv


def stack(x, y, z):
    return np.stack([x, y, z], axis=1).astype(np.float64)


def sample_wm(u):
    u1, u2 = uniforms(u)
    phi = F32(2.0) * PI * u1
    r2 = u2 / (F32(1.0) - u2)
    rho = np.sqrt(r2) if RHO_EXPONENT is None else np.power(r2, RHO_EXPONENT)
    return stack(*normalize(AX * rho * np.cos(phi), AY * rho * np.sin(phi), np.ones_like(rho)))


def pdf_wm(m):
    x, y, z = f32(m)
    return np.where(z > F32(0.0), d_f32(x, y, z) * z, F32(0.0)).astype(np.float64)


def sample_wm_visible(wi, u):
    wx, wy, wz = f32(wi)
    u1, u2 = uniforms(u)
    # Stretch to alpha = 1: the visible normals are those of a hemisphere.
    vx, vy, vz = normalize(AX * wx, AY * wy, wz)
    l2 = vx * vx + vy * vy
    has_azimuth = l2 > F32(0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        il = F32(1.0) / np.sqrt(l2)
        t1x = np.where(has_azimuth, -vy * il, F32(1.0))
        t1y = np.where(has_azimuth, vx * il, F32(0.0))
    # T2 = V x T1 (T1 has no z component).
    t2x, t2y, t2z = -vz * t1y, vz * t1x, vx * t1y - vy * t1x
    # A uniform point of the disk, its T2 coordinate warped onto the projected half-disk.
    r = np.sqrt(u1)
    phi = F32(2.0) * PI * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    s = F32(0.5) * (F32(1.0) + vz)
    p2 = (F32(1.0) - s) * np.sqrt(np.maximum(F32(0.0), F32(1.0) - p1 * p1)) + s * p2
    p3 = np.sqrt(np.maximum(F32(0.0), F32(1.0) - p1 * p1 - p2 * p2))
    hx = p1 * t1x + p2 * t2x + p3 * vx
    hy = p1 * t1y + p2 * t2y + p3 * vy
    hz = p2 * t2z + p3 * vz
    # Unstretch.
    return stack(*normalize(AX * hx, AY * hy, np.maximum(F32(1e-6), hz)))


def pdf_wm_visible(wi, m):
    wx, wy, wz = f32(wi)
    mx, my, mz = f32(m)
    c = np.maximum(F32(0.0), wx * mx + wy * my + wz * mz)
    g1 = F32(1.0) / (F32(1.0) + lambda_f32(wx, wy, wz))
    with np.errstate(divide="ignore", invalid="ignore"):
        v = g1 / wz * d_f32(mx, my, mz) * c
    return np.where(wz > F32(0.0), v, F32(0.0)).astype(np.float64)


if __name__ == "__main__":
    name = "ggx_f32_numpy.py" + ("" if DEFECT == "none" else " --defect " + DEFECT)
    parameters = {"family": "ggx", "alpha_x": AX64, "alpha_y": AY64}
    if DEFECT != "none":
        parameters["defect"] = DEFECT
    mfh_protocol.serve(
        name,
        parameters,
        {"d": d, "lambda": lam, "sample_wm": sample_wm, "pdf_wm": pdf_wm,
         "sample_wm_visible": sample_wm_visible, "pdf_wm_visible": pdf_wm_visible},
        protocol=PROTOCOL,
        numpy=True,
        extra={"precision": "f32"},
    )
