#!/usr/bin/env python3
"""A rough dielectric BSDF (Walter, Marschner, Li & Torrance 2007, "Microfacet models for
refraction through rough surfaces") speaking mfh's external protocol: reflection and refraction
through a GGX interface, lit from either side, with total internal reflection.

Pure Python, no dependencies. Run by mfh:

    mfh audit-external --cmd "python3 examples/external/dielectric.py" --profile ci \
        --against '{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}'

Options: --alpha A (isotropic GGX, default 0.3), --eta E (eta inside / eta outside, default
1.5), --protocol 1|2 (default 2), --workers N (processes sharing large batches, default
min(2, cores)), --defect refraction_jacobian (a classic bug, for the audit to
find: the pdf of refracted directions without the Jacobian dwh/dwo), --ndf ggx (also offer the
GGX NDF it is built on, capabilities "d" and "lambda", and declare the BSDF's "masking" and
"sampling" in describe: mfh then audits that NDF too and compares the BSDF with Walter's
formulas built from it, bsdf.ndf_consistency, which the defect fails).

Conventions (reference/src/bsdf/mod.rs): local frame, macro-normal +z pointing outside; wi and
wo both point away from the surface, either hemisphere; eval = f(wi, wo) |wo_z|; pdf is the
solid-angle density of the wo that sample returns; radiance transport (the transmission term is
Walter's eq 21 times (eta_i/eta_o)^2, eta_i the index on wi's side).

    reflection (wi_z wo_z > 0):   h = sign(wi_z)(wi + wo)/|wi + wo|                 (eq 13)
        f = F(wi, h) G2 D(h) / (4 |wi_z| |wo_z|)                                      (eq 20)
        pdf = F(wi, h) p_m(h) / (4 |wo.h|)                                            (eq 14)
    refraction (wi_z wo_z < 0):   h = -(eta_i wi + eta_o wo)/|...|, h_z > 0           (eq 16)
        f = |wi.h||wo.h|/(|wi_z||wo_z|) eta_o^2 (1 - F) G2 D / |eta_i wi + eta_o wo|^2 (eq 21)
        pdf = (1 - F) p_m(h) eta_o^2 |wo.h| / |eta_i wi + eta_o wo|^2                 (eq 17)
    G2 = 1/(1 + L(wi+) + L(wo+)) (height-correlated, both lobes), w+ = w or -w above the
    surface; side conditions (wi.h) wi_z > 0 and (wo.h) wo_z > 0; F exact (eq 22);
    p_m = GGX visible normals at wi+ (Heitz 2018), sampled by u1, u2; u0 < F reflects.

stdout is the protocol channel: log to stderr only.
"""
import math
import os
import sys

import mfh_protocol

ARGS = dict(zip(sys.argv[1::2], sys.argv[2::2]))
A = float(ARGS.get("--alpha", 0.3))
ETA = float(ARGS.get("--eta", 1.5))
PROTOCOL = int(ARGS.get("--protocol", 2))
DEFECT = ARGS.get("--defect")
NDF = ARGS.get("--ndf")
if NDF not in (None, "ggx"):
    sys.exit("--ndf must be ggx")
# Processes that share a large batch (default: one per core, at most 2).
WORKERS = int(ARGS.get("--workers", min(2, os.cpu_count() or 1)))
if DEFECT not in (None, "refraction_jacobian"):
    sys.exit("--defect must be refraction_jacobian")
if PROTOCOL not in mfh_protocol.VERSIONS:
    sys.exit("--protocol must be one of %s" % (mfh_protocol.VERSIONS,))
JACOBIAN = DEFECT != "refraction_jacobian"

A2 = A * A
INV_PI_A2 = 1.0 / (math.pi * A2)
TWO_PI = 2.0 * math.pi
sqrt = math.sqrt
isfinite = math.isfinite


def lam(x, y, z):
    """Smith Lambda of GGX at w+ (isotropic: depends on |z| only), z != 0."""
    t = A2 * (x * x + y * y) / (z * z)
    if t == 0.0:
        return 0.0
    return t / (2.0 * (1.0 + sqrt(1.0 + t)))


def ggx_d(mx, my, mz):
    """D(m) for m_z > 0."""
    z2 = mz * mz
    s = 1.0 + (mx * mx + my * my) / (A2 * z2)
    return INV_PI_A2 / (z2 * z2 * s * s)


def ndf_d(m):
    """The NDF capability d: D(m), 0 below the horizon."""
    return ggx_d(*m) if m[2] > 0.0 else 0.0


def ndf_lambda(w):
    """The NDF capability lambda: Lambda(w), with Lambda(-w) = -1 - Lambda(w) below."""
    x, y, z = w
    if z == 0.0:
        return math.inf if x * x + y * y > 0.0 else 0.0
    return lam(x, y, z) if z > 0.0 else -1.0 - lam(x, y, z)


def fresnel(c, eta):
    """(reflectance, transmittance, cos_t) at |cos| c, eta = eta_t/eta_i (Walter eq 22, in
    forms without cancellation)."""
    c = abs(c)
    if c > 1.0:
        c = 1.0
    e2 = eta * eta
    em1 = (eta - 1.0) * (eta + 1.0)
    g2 = em1 + c * c
    if not g2 > 0.0:
        return 1.0, 0.0, 0.0
    g = sqrt(g2)
    s = c + g
    p = e2 * c + g
    rs = -em1 / (s * s)
    rp = em1 * ((e2 + 1.0) * c * c - 1.0) / (p * p)
    r = 0.5 * (rs * rs + rp * rp)
    t = 2.0 * c * g * (1.0 / (s * s) + e2 / (p * p))
    return min(r, 1.0), min(max(t, 0.0), 1.0), min(g / eta, 1.0)


def pdf_m(wx, wy, wz, mx, my, mz, d, lam_w):
    """Density of the visible normal m at w+ (D(m) = d and Lambda(w+) = lam_w given)."""
    if wz < 0.0:
        wx, wy, wz = -wx, -wy, -wz
    c = wx * mx + wy * my + wz * mz
    if not (wz > 0.0 and mz > 0.0 and c > 0.0):
        return 0.0
    return c * d / (wz * (1.0 + lam_w))


def evaluate(wi, wo):
    """(eval, pdf) at (wi, wo)."""
    ix, iy, ci = wi
    ox, oy, co = wo
    if ci == 0.0 or co == 0.0 or not isfinite(ix + iy + ci + ox + oy + co):
        return 0.0, 0.0
    if ci * co > 0.0:
        hx, hy, hz = ix + ox, iy + oy, ci + co
        length = sqrt(hx * hx + hy * hy + hz * hz)
        if not length > 0.0:
            return 0.0, 0.0
        s = (1.0 if ci > 0.0 else -1.0) / length
        mx, my, mz = s * hx, s * hy, s * hz
        cim = ix * mx + iy * my + ci * mz
        com = ox * mx + oy * my + co * mz
        if not (mz > 0.0 and cim * ci > 0.0 and com * co > 0.0):
            return 0.0, 0.0
        c = 0.5 * length
        f = fresnel(c, ETA if ci > 0.0 else 1.0 / ETA)[0]
        d = ggx_d(mx, my, mz)
        lam_i = lam(ix, iy, ci)
        g = 1.0 / (1.0 + lam_i + lam(ox, oy, co))
        value = f * g * d / (4.0 * abs(ci))
        pdf = f * pdf_m(ix, iy, ci, mx, my, mz, d, lam_i) / (4.0 * c)
    else:
        eta_i = 1.0 if ci > 0.0 else ETA
        eta_o = 1.0 if co > 0.0 else ETA
        vx = eta_i * ix + eta_o * ox
        vy = eta_i * iy + eta_o * oy
        vz = eta_i * ci + eta_o * co
        len2 = vx * vx + vy * vy + vz * vz
        length = sqrt(len2)
        if not length > 0.0:
            return 0.0, 0.0
        s = 1.0 / length if vz > 0.0 else -1.0 / length
        mx, my, mz = s * vx, s * vy, s * vz
        cim = ix * mx + iy * my + ci * mz
        com = ox * mx + oy * my + co * mz
        if not (mz > 0.0 and cim * ci > 0.0 and com * co > 0.0):
            return 0.0, 0.0
        if eta_i < eta_o:
            t = fresnel(cim, eta_o / eta_i)[1]
        else:
            t = fresnel(com, eta_i / eta_o)[1]
        if not t > 0.0:
            return 0.0, 0.0
        d = ggx_d(mx, my, mz)
        lam_i = lam(ix, iy, ci)
        g = 1.0 / (1.0 + lam_i + lam(ox, oy, co))
        jacobian = eta_o * eta_o * abs(com) / len2
        ratio = eta_i / eta_o
        value = abs(cim) * t * g * d * jacobian / abs(ci) * (ratio * ratio)
        pdf = t * pdf_m(ix, iy, ci, mx, my, mz, d, lam_i) * (jacobian if JACOBIAN else 1.0)
    if not isfinite(value):
        value = 0.0
    if not isfinite(pdf):
        pdf = 0.0
    return value, pdf


def bsdf_eval(wi, wo):
    return evaluate(wi, wo)[0]


def bsdf_pdf(wi, wo):
    return evaluate(wi, wo)[1]


_frame = [None, None]


def frame(wi):
    """The visible-normal frame of wi+ (Heitz 2018), cached for the last wi (a batch shares
    it)."""
    if _frame[0] == wi:
        return _frame[1]
    x, y, z = wi
    if z < 0.0:
        x, y, z = -x, -y, -z
    vx, vy, vz = A * x, A * y, z
    n = sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / n, vy / n, vz / n
    l2 = vx * vx + vy * vy
    if l2 > 0.0:
        il = 1.0 / sqrt(l2)
        t1 = (-vy * il, vx * il, 0.0)
    else:
        t1 = (1.0, 0.0, 0.0)
    t2 = (vy * t1[2] - vz * t1[1], vz * t1[0] - vx * t1[2], vx * t1[1] - vy * t1[0])
    f = ((x, y, z), (vx, vy, vz), t1, t2, 0.5 * (1.0 + vz))
    _frame[0], _frame[1] = wi, f
    return f


FAILED = ((0.0, 0.0, 1.0), 0.0, 0.0)


def bsdf_sample(wi, u):
    """(wo, pdf, weight) for wi and u in [0,1)^3, or FAILED."""
    ci = wi[2]
    if ci == 0.0 or not isfinite(wi[0] + wi[1] + ci):
        return FAILED
    (px, py, pz), (vx, vy, vz), t1, t2v, s = frame(wi)
    # Heitz 2018: a point on the projected hemisphere, r = sqrt(u1), phi = 2 pi u2.
    r = sqrt(u[1])
    phi = TWO_PI * u[2]
    a = r * math.cos(phi)
    b = (1.0 - s) * sqrt(max(0.0, 1.0 - a * a)) + s * r * math.sin(phi)
    lift = sqrt(max(0.0, 1.0 - a * a - b * b))
    hx = a * t1[0] + b * t2v[0] + lift * vx
    hy = a * t1[1] + b * t2v[1] + lift * vy
    hz = a * t1[2] + b * t2v[2] + lift * vz
    mx, my, mz = A * hx, A * hy, max(0.0, hz)
    n = sqrt(mx * mx + my * my + mz * mz)
    mx, my, mz = mx / n, my / n, mz / n
    if not (mz > 0.0 and px * mx + py * my + pz * mz > 0.0 and isfinite(mx + my)):
        return FAILED
    ix, iy = wi[0], wi[1]
    c = ix * mx + iy * my + ci * mz
    other = ETA if ci > 0.0 else 1.0 / ETA
    reflectance, _, cos_t = fresnel(c, other)
    reflected = u[0] < reflectance
    if reflected:
        k = 2.0 * c
        wo = (k * mx - ix, k * my - iy, k * mz - ci)
    else:
        e = 1.0 / other
        k = (e * abs(c) - cos_t) * math.copysign(1.0, c)
        wo = (-e * ix + k * mx, -e * iy + k * my, -e * ci + k * mz)
    if wo[2] == 0.0 or (wo[2] * ci > 0.0) != reflected or not isfinite(wo[0] + wo[1] + wo[2]):
        return FAILED
    value, pdf = evaluate(wi, wo)
    if not pdf > 0.0:
        return FAILED
    return wo, pdf, value / pdf


def main():
    name = "dielectric.py" + (" --defect " + DEFECT if DEFECT else "")
    functions = {"bsdf_eval": bsdf_eval, "bsdf_pdf": bsdf_pdf, "bsdf_sample": bsdf_sample}
    # Its sample map is mfh's reference map (visible normals: u1 the disk radius, u2 the
    # azimuth; u0 the lobe), so it declares it and mfh compares its directions for each u too.
    extra = {"eta": ETA, "transport": "radiance", "reference_map": "visible_normals"}
    if NDF:
        name += " --ndf " + NDF
        functions = dict({"d": ndf_d, "lambda": ndf_lambda}, **functions)
        extra.update(masking="height_correlated", sampling="visible_normals")
    mfh_protocol.serve(
        name,
        {"ndf": {"family": "ggx", "alpha": A}, "eta": ETA, "masking": "height_correlated",
         "sampling": "visible_normals", "defect": DEFECT},
        functions,
        protocol=PROTOCOL,
        extra=extra,
        workers=WORKERS,
    )


if __name__ == "__main__":
    main()
