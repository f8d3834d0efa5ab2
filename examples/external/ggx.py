#!/usr/bin/env python3
"""A GGX (Trowbridge-Reitz) microfacet model speaking mfh's external protocol (version 2, or
1 with --protocol 1; the protocol loop is mfh_protocol.py beside this file).

Pure Python, no dependencies. Run by mfh:

    mfh audit-external --cmd "python3 examples/external/ggx.py" --profile ci \
        --against '{"family":"ggx","alpha_x":0.3,"alpha_y":0.3}'

Options: --alpha A (isotropic) or --alpha-x AX --alpha-y AY (default 0.3), --protocol 1|2.
stdout is the protocol channel: log to stderr only.
"""
import math

import mfh_protocol

AX, AY, PROTOCOL = mfh_protocol.options()
PI = math.pi


def d(m):
    x, y, z = m
    if z <= 0.0:
        return 0.0
    z2 = z * z
    s2 = ((x / AX) ** 2 + (y / AY) ** 2) / z2
    return 1.0 / (PI * AX * AY * z2 * z2 * (1.0 + s2) ** 2)


def lam(w):
    x, y, z = w
    if z < 0.0:
        return -1.0 - lam((-x, -y, -z))
    t2 = (AX * x) ** 2 + (AY * y) ** 2
    if t2 == 0.0:
        return 0.0
    if z == 0.0:
        return math.inf
    inv_a2 = t2 / (z * z)
    # (sqrt(1 + a^-2) - 1) / 2 without cancellation.
    return inv_a2 / (2.0 * (1.0 + math.sqrt(1.0 + inv_a2)))


def sample_wm(u):
    # Slope (AX rho cos phi, AY rho sin phi), rho^2 = u2 / (1 - u2), phi = 2 pi u1.
    phi = 2.0 * PI * u[0]
    rho = math.sqrt(u[1] / (1.0 - u[1]))
    px, py = AX * rho * math.cos(phi), AY * rho * math.sin(phi)
    n = math.sqrt(1.0 + px * px + py * py)
    return [-px / n, -py / n, 1.0 / n]


def pdf_wm(m):
    return d(m) * m[2] if m[2] > 0.0 else 0.0


def sample_wm_visible(wi, u):
    # Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4).
    vx, vy, vz = AX * wi[0], AY * wi[1], wi[2]
    n = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / n, vy / n, vz / n
    l2 = vx * vx + vy * vy
    if l2 > 0.0:
        il = 1.0 / math.sqrt(l2)
        t1 = (-vy * il, vx * il, 0.0)
    else:
        t1 = (1.0, 0.0, 0.0)
    t2 = (vy * t1[2] - vz * t1[1], vz * t1[0] - vx * t1[2], vx * t1[1] - vy * t1[0])
    r = math.sqrt(u[0])
    phi = 2.0 * PI * u[1]
    p1, p2 = r * math.cos(phi), r * math.sin(phi)
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * math.sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2
    p3 = math.sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2))
    hx = p1 * t1[0] + p2 * t2[0] + p3 * vx
    hy = p1 * t1[1] + p2 * t2[1] + p3 * vy
    hz = p1 * t1[2] + p2 * t2[2] + p3 * vz
    mx, my, mz = AX * hx, AY * hy, max(1e-300, hz)
    n = math.sqrt(mx * mx + my * my + mz * mz)
    return [mx / n, my / n, mz / n]


def pdf_wm_visible(wi, m):
    c = wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2]
    if m[2] <= 0.0 or c <= 0.0:
        return 0.0
    return c * d(m) / (wi[2] * (1.0 + lam(wi)))


def main(name="ggx.py", sampler=sample_wm):
    """Serves the protocol; another example may pass its own name and sampler."""
    mfh_protocol.serve(
        name,
        {"family": "ggx", "alpha_x": AX, "alpha_y": AY},
        {"d": d, "lambda": lam, "sample_wm": sampler, "pdf_wm": pdf_wm,
         "sample_wm_visible": sample_wm_visible, "pdf_wm_visible": pdf_wm_visible},
        protocol=PROTOCOL,
    )


if __name__ == "__main__":
    main()
