#!/usr/bin/env python3
"""A float32 rough dielectric BSDF speaking mfh's external protocol, vectorized with numpy:
reflection and refraction through a GGX interface (Walter, Marschner, Li & Torrance 2007), lit
from either side, with total internal reflection, written as pbrt-v4's `DielectricBxDF` writes
its rough path and with every array and every operation float32, as in a renderer whose `Float`
is 32 bits. mfh's float64 arrays are rounded to float32 on the way in, the answers widened on
the way out; describe declares "precision": "f32", "eta" and "transport": "radiance". Run by
mfh:

    mfh audit-external --cmd "python3 examples/external/dielectric_f32_numpy.py" --profile ci \
        --against '{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}'

Options: --alpha A (isotropic GGX, default 0.3), --eta E (eta inside / eta outside, default
1.5), --protocol 1|2 (default 2), --defect jacobian_wi: the refraction Jacobian |dwm/dwo| with
the cosine of the wrong side, |wi.m| for |wo.m| (in pdf and sample alike, so the two stay
consistent with each other and only the density of the sampled directions is wrong: mfh's
bsdf.chi2 sees it).

Conventions (mfh's, reference/src/bsdf/mod.rs): wi is the camera side (pbrt's wo), wo the
sampled one (pbrt's wi); eval = f(wi, wo) |wo_z|; radiance transport: the BTDF divided by
eta'^2, eta' the far side's index over wi's (pbrt-v4's TransportMode::Radiance).

    eta' = 1 (reflection), eta (wi outside), 1/eta (wi inside)
    wm = normalize(eta' wo + wi), flipped to wm_z > 0; 0 unless (wm.wi) wi_z > 0, (wm.wo) wo_z > 0
    F = FrDielectric(wi.wm, eta) (exact, eq 22); G = 1/(1 + L(wi) + L(wo)) (height-correlated)
    reflection: f = F D G / |4 wi_z wo_z|;            pdf = p(wi, wm) F / (4 |wi.wm|)
    refraction: f = (1 - F) D G |wo.wm wi.wm| / (|wi_z wo_z| (wo.wm + wi.wm/eta')^2) / eta'^2
                pdf = p(wi, wm) (1 - F) |wo.wm| / (wo.wm + wi.wm/eta')^2
    p(w, m) = G1(w+) D(m) |w.m| / w+_z, the GGX visible-normal density (w+ = w or -w above)
    D(m) = 1 / (pi a^2 (x^2/a^2 + y^2/a^2 + z^2)^2) (no guard needed up to the horizon)
    sample: m from visible normals at wi+ (Heitz 2018) by u1, u2; u0 < F reflects, else refracts.

Uniforms are rounded to float32 and kept below 1 (1 - 2^-24). Log to stderr only.
"""
import sys

import mfh_protocol
import numpy as np

F32 = np.float32
ONE_MINUS_EPSILON = F32(1.0) - F32(2.0**-24)
PI = F32(np.pi)

ARGS = dict(zip(sys.argv[1::2], sys.argv[2::2]))
ALPHA64 = float(ARGS.get("--alpha", 0.3))
ETA64 = float(ARGS.get("--eta", 1.5))
PROTOCOL = int(ARGS.get("--protocol", 2))
DEFECT = ARGS.get("--defect")
if DEFECT not in (None, "jacobian_wi"):
    sys.exit("--defect is %r; known: jacobian_wi" % DEFECT)
if PROTOCOL not in mfh_protocol.VERSIONS:
    sys.exit("--protocol must be one of %s" % (mfh_protocol.VERSIONS,))
if not (ALPHA64 > 0.0 and 0.1 <= ETA64 <= 10.0 and abs(ETA64 - 1.0) >= 5e-5):
    sys.exit("--alpha must be > 0 and --eta in [0.1, 10], at least 5e-5 from 1")
A = F32(ALPHA64)
A2 = A * A
ETA = F32(ETA64)
ONE, ZERO = F32(1.0), F32(0.0)


def columns(a):
    """A request array (n, 3) as float32 arrays x, y, z."""
    a = np.asarray(a, dtype=F32)
    return a[:, 0], a[:, 1], a[:, 2]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def upper(w):
    """w or -w, whichever is above the surface."""
    s = np.where(w[2] < ZERO, F32(-1.0), ONE)
    return (w[0] * s, w[1] * s, w[2] * s)


def normalize(w):
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = ONE / np.sqrt(dot(w, w))
    return (w[0] * inv, w[1] * inv, w[2] * inv)


def d(m):
    t = (m[0] * m[0] + m[1] * m[1]) / A2 + m[2] * m[2]
    with np.errstate(divide="ignore", over="ignore"):
        v = ONE / (PI * A2 * t * t)
    return np.where(m[2] > ZERO, v, ZERO)


def lam(w):
    """Lambda of a direction on either side (even in cos theta, as pbrt's)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        tan2 = (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2])
        return (np.sqrt(ONE + A2 * tan2) - ONE) / F32(2.0)


def g2(i, o):
    return ONE / (ONE + lam(i) + lam(o))


def visible_pdf(w, m):
    w = upper(w)
    with np.errstate(divide="ignore", invalid="ignore"):
        return d(m) * np.abs(dot(w, m)) / ((ONE + lam(w)) * w[2])


def fresnel(cos, eta):
    """pbrt-v4's FrDielectric: cos of the incident side, eta the far side's index over it."""
    cos = np.clip(cos, F32(-1.0), ONE)
    inside = cos < ZERO
    eta = np.where(inside, ONE / eta, eta)
    c = np.abs(cos)
    sin2_t = (ONE - c * c) / (eta * eta)
    cos_t = np.sqrt(np.maximum(ZERO, ONE - sin2_t))
    with np.errstate(divide="ignore", invalid="ignore"):
        r_parl = (eta * c - cos_t) / (eta * c + cos_t)
        r_perp = (c - eta * cos_t) / (c + eta * cos_t)
    return np.where(sin2_t >= ONE, ONE, (r_parl * r_parl + r_perp * r_perp) / F32(2.0))


def refraction_jacobian(i, o, m, etap):
    """|dwm/dwo| (pbrt-v4's dwm_dwi) and the squared denominator it shares with f."""
    denom = dot(o, m) + dot(i, m) / etap
    denom2 = denom * denom
    c = dot(i, m) if DEFECT == "jacobian_wi" else dot(o, m)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(c) / denom2, denom2


def lobes(i, o, m, etap, r, reflect):
    """(f |wo_z|, pdf) of each lobe through the microfacet normal m."""
    dm, g, p = d(m), g2(i, o), visible_pdf(i, m)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        f_r = r * dm * g / np.abs(F32(4.0) * i[2] * o[2])
        p_r = p / (F32(4.0) * np.abs(dot(i, m))) * r
        jacobian, denom2 = refraction_jacobian(i, o, m, etap)
        t = ONE - r
        f_t = t * dm * g * np.abs(dot(o, m) * dot(i, m)) / (np.abs(i[2] * o[2]) * denom2)
        f_t = f_t / (etap * etap)
        p_t = p * jacobian * t
    f = np.where(reflect, f_r, f_t) * np.abs(o[2])
    pdf = np.where(reflect, p_r, p_t)
    return f, pdf


def eval_pdf(wi, wo):
    i, o = columns(wi), columns(wo)
    reflect = i[2] * o[2] > ZERO
    etap = np.where(reflect, ONE, np.where(i[2] > ZERO, ETA, ONE / ETA))
    wm = normalize((o[0] * etap + i[0], o[1] * etap + i[1], o[2] * etap + i[2]))
    wm = upper(wm)
    ok = (i[2] != ZERO) & (o[2] != ZERO) & np.isfinite(wm[2])
    ok &= (dot(wm, o) * o[2] >= ZERO) & (dot(wm, i) * i[2] >= ZERO)
    r = fresnel(dot(i, wm), ETA)
    f, pdf = lobes(i, o, wm, etap, r, reflect)
    good = ok & np.isfinite(f) & np.isfinite(pdf)
    return np.where(good, f, ZERO), np.where(good, pdf, ZERO)


def bsdf_eval(wi, wo):
    return eval_pdf(wi, wo)[0].astype(np.float64)


def bsdf_pdf(wi, wo):
    return eval_pdf(wi, wo)[1].astype(np.float64)


def visible_normal(w, u1, u2):
    """Heitz 2018 (JCGT 7(4)) at w above the surface, in float32."""
    v = normalize((A * w[0], A * w[1], w[2]))
    l2 = v[0] * v[0] + v[1] * v[1]
    has_azimuth = l2 > ZERO
    with np.errstate(divide="ignore", invalid="ignore"):
        il = ONE / np.sqrt(l2)
    t1 = (np.where(has_azimuth, -v[1] * il, ONE), np.where(has_azimuth, v[0] * il, ZERO))
    t2 = (-v[2] * t1[1], v[2] * t1[0], v[0] * t1[1] - v[1] * t1[0])
    r = np.sqrt(u1)
    phi = F32(2.0) * PI * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    s = F32(0.5) * (ONE + v[2])
    p2 = (ONE - s) * np.sqrt(np.maximum(ZERO, ONE - p1 * p1)) + s * p2
    p3 = np.sqrt(np.maximum(ZERO, ONE - p1 * p1 - p2 * p2))
    h = (p1 * t1[0] + p2 * t2[0] + p3 * v[0], p1 * t1[1] + p2 * t2[1] + p3 * v[1],
         p2 * t2[2] + p3 * v[2])
    return normalize((A * h[0], A * h[1], np.maximum(F32(1e-6), h[2])))


def bsdf_sample(wi, u):
    i = columns(wi)
    u = np.minimum(np.asarray(u, dtype=F32), ONE_MINUS_EPSILON)
    m = visible_normal(upper(i), u[:, 1], u[:, 2])
    cos_im = dot(i, m)
    r = fresnel(cos_im, ETA)
    reflect = u[:, 0] < r
    # Reflection about m, and pbrt-v4's Refract through m from wi's side.
    o_r = tuple(F32(2.0) * cos_im * m[k] - i[k] for k in range(3))
    inside = cos_im < ZERO
    eta = np.where(inside, ONE / ETA, ETA)
    n = tuple(np.where(inside, -m[k], m[k]) for k in range(3))
    c = np.abs(cos_im)
    sin2_t = np.maximum(ZERO, ONE - c * c) / (eta * eta)
    tir = sin2_t >= ONE
    cos_t = np.sqrt(np.maximum(ZERO, ONE - sin2_t))
    o_t = tuple(-i[k] / eta + (c / eta - cos_t) * n[k] for k in range(3))
    o = tuple(np.where(reflect, o_r[k], o_t[k]) for k in range(3))
    etap = np.where(reflect, ONE, eta)
    f, pdf = lobes(i, o, m, etap, r, reflect)
    side = o[2] * i[2]
    failed = np.where(reflect, side <= ZERO, tir | (side >= ZERO))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        weight = f / pdf
    failed |= ~(pdf > ZERO) | ~np.isfinite(pdf) | ~np.isfinite(weight)
    wo = np.stack(o, axis=1).astype(np.float64)
    wo[failed] = (0.0, 0.0, 1.0)
    pdf = np.where(failed, ZERO, pdf).astype(np.float64)
    weight = np.where(failed, ZERO, weight).astype(np.float64)
    return wo, pdf, weight


if __name__ == "__main__":
    name = "dielectric_f32_numpy.py" + ("" if DEFECT is None else " --defect " + DEFECT)
    parameters = {"bsdf": "dielectric", "ndf": "ggx", "alpha": ALPHA64, "eta": ETA64}
    if DEFECT is not None:
        parameters["defect"] = DEFECT
    mfh_protocol.serve(
        name,
        parameters,
        {"bsdf_eval": bsdf_eval, "bsdf_pdf": bsdf_pdf, "bsdf_sample": bsdf_sample},
        protocol=PROTOCOL,
        numpy=True,
        extra={"precision": "f32", "eta": float(ETA), "transport": "radiance"},
    )
