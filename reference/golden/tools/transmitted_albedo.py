#!/usr/bin/env python3
"""Generates reference/golden/transmitted_albedo.json: the transmitted part of the albedo
(∫ eval dωo over the far hemisphere) of the reference rough dielectric at grazing incidence,
computed over the microfacet normals instead of the scattered directions, independently of
the Rust code and of its cubature over wo.

Why over the normals: for refraction, f_t |wo.n| dωo = (|wi.m|/|wi.n|) (1 - F(wi.m)) G2 D(m) dωm
(Walter, Marschner, Li & Torrance 2007, eq 21 times the Jacobian of eq 17: the factor
eta_o^2 |wo.m| / (eta_i wi.m + eta_o wo.m)^2 cancels), so the integrand is smooth in m even
where the lobe in wo is 1e-4 wide (eta -> 1) or ends in a step (GGX's D is not 0 at the
microfacets' horizon, whose refracted directions all lie at |wo_z| = |wi_z| / eta).

What is computed, for each configuration: wi at cos(theta_i) = 0.05, phi_i = 0.3 from outside
(eta = eta_inside/eta_outside); m over the half-space wi.m > 0, m_z > 0, as theta_m in
[0, theta_max(phi)] (the limit where wi.m = 0) by Gauss-Legendre per phi node, phi split at
phi_i +- pi/2 where theta_max has kinks; wo = (c/eta - sqrt(1 - (1 - c^2)/eta^2)) m - wi/eta
(c = wi.m); F the exact dielectric Fresnel reflectance (Walter eq 22); G2 height-correlated
1/(1 + Lambda(wi) + Lambda(wo)) (Heitz 2014 §6); GGX D and Lambda in closed form, Beckmann's
with erfc; radiance transport, the mfh default: times (eta_i/eta_o)^2 = 1/eta^2. Each value
with 400x800 and 800x1600 nodes; the file keeps the finer and their difference
("quadrature_difference").

Usage: python3 reference/golden/tools/transmitted_albedo.py > reference/golden/transmitted_albedo.json
Requires: numpy.
"""
import json
import math

import numpy as np

COS_I, PHI_I, ALPHA = 0.05, 0.3, 0.3
CONFIGS = [("ggx", e) for e in (1.00005, 1.0005, 1.005, 1.05, 1.5)] + [
    ("beckmann", e) for e in (1.005, 1.05)
]
erfc = np.vectorize(math.erfc)


def lam(family, z):
    z = np.abs(z)
    t = np.sqrt(1 - z * z) / z
    if family == "ggx":
        return 0.5 * (-1 + np.sqrt(1 + (ALPHA * t) ** 2))
    a = 1 / (ALPHA * t)
    return (np.exp(-a * a) - a * np.sqrt(np.pi) * erfc(a)) / (2 * a * np.sqrt(np.pi))


def d(family, z):
    t2 = (1 - z * z) / (z * z)
    if family == "ggx":
        return 1 / (np.pi * ALPHA**2 * z**4 * (1 + t2 / ALPHA**2) ** 2)
    return np.exp(-t2 / ALPHA**2) / (np.pi * ALPHA**2 * z**4)


def fresnel(c, eta):
    g2 = eta * eta - 1 + c * c
    g = np.sqrt(np.maximum(g2, 0))
    f = 0.5 * ((g - c) / (g + c)) ** 2 * (1 + ((c * (g + c) - 1) / (c * (g - c) + 1)) ** 2)
    return np.where(g2 < 0, 1.0, f)


def transmitted(family, eta, nth, nph):
    si = math.sqrt(1 - COS_I**2)
    wi = np.array([si * math.cos(PHI_I), si * math.sin(PHI_I), COS_I])
    xg, wg = np.polynomial.legendre.leggauss(nth)
    xp, wp = np.polynomial.legendre.leggauss(nph)
    edges = [0.0, PHI_I + np.pi / 2, PHI_I + 3 * np.pi / 2, 2 * np.pi]
    total = 0.0
    for a, b in zip(edges[:-1], edges[1:]):
        ph = 0.5 * (b - a) * xp + 0.5 * (b + a)
        wph = 0.5 * (b - a) * wp
        cd = np.cos(ph - PHI_I)
        thmax = np.where(cd < 0, np.arctan2(COS_I, si * (-cd)), np.pi / 2)
        th = 0.5 * thmax[None, :] * (xg[:, None] + 1)
        wth = 0.5 * thmax[None, :] * wg[:, None]
        phi = np.broadcast_to(ph[None, :], th.shape)
        m = np.array([np.sin(th) * np.cos(phi), np.sin(th) * np.sin(phi), np.cos(th)])
        c = wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2]
        k = 1 - (1 - c * c) / (eta * eta)
        wo_z = (c / eta - np.sqrt(np.maximum(k, 0))) * m[2] - wi[2] / eta
        valid = (c > 0) & (k > 0) & (wo_z < 0)
        g2 = 1 / (1 + lam(family, wi[2]) + lam(family, wo_z))
        f = (1 - fresnel(c, eta)) * c * g2 * d(family, m[2]) / COS_I * np.sin(th)
        total += np.sum(np.where(valid, f, 0.0) * wth * wph[None, :])
    return total / eta**2


def main():
    rows = []
    for family, eta in CONFIGS:
        coarse = transmitted(family, eta, 400, 800)
        fine = transmitted(family, eta, 800, 1600)
        rows.append({"family": family, "alpha": ALPHA, "eta": eta, "transmitted": fine,
                     "quadrature_difference": abs(fine - coarse)})
    print(json.dumps({
        "provenance": {
            "command": "python3 reference/golden/tools/transmitted_albedo.py > "
                       "reference/golden/transmitted_albedo.json",
            "source": "Walter et al. 2007 eq 17, 21, 22 over the microfacet normals; Heitz 2014 §6",
            "incidence": {"cos_theta": COS_I, "phi": PHI_I, "side": "outside"},
            "transport": "radiance",
        },
        "rows": rows,
    }, indent=1))


if __name__ == "__main__":
    main()
