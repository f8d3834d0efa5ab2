#!/usr/bin/env python3
"""A Beckmann microfacet model speaking mfh's external protocol (version 2, or 1 with
--protocol 1; the protocol loop is mfh_protocol.py beside this file).

Pure Python, no dependencies. Run by mfh:

    mfh audit-external --cmd "python3 examples/external/beckmann.py" --profile ci \
        --against '{"family":"beckmann","alpha_x":0.3,"alpha_y":0.3}'

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
    return math.exp(-s2) / (PI * AX * AY * z2 * z2)


def lam(w):
    x, y, z = w
    if z < 0.0:
        return -1.0 - lam((-x, -y, -z))
    t2 = (AX * x) ** 2 + (AY * y) ** 2
    if t2 == 0.0:
        return 0.0
    if z == 0.0:
        return math.inf
    a = z / math.sqrt(t2)
    if a > 26.0:
        return 0.0  # exp(-a^2) < 1e-293: Lambda underflows
    return (math.exp(-a * a) / (a * math.sqrt(PI)) - math.erfc(a)) / 2.0


def sample_wm(u):
    # Slope (AX rho cos phi, AY rho sin phi), rho^2 = -ln(1 - u2), phi = 2 pi u1.
    phi = 2.0 * PI * u[0]
    rho = math.sqrt(-math.log1p(-u[1]))
    px, py = AX * rho * math.cos(phi), AY * rho * math.sin(phi)
    n = math.sqrt(1.0 + px * px + py * py)
    return [-px / n, -py / n, 1.0 / n]


def pdf_wm(m):
    return d(m) * m[2] if m[2] > 0.0 else 0.0


if __name__ == "__main__":
    mfh_protocol.serve(
        "beckmann.py",
        {"family": "beckmann", "alpha_x": AX, "alpha_y": AY},
        {"d": d, "lambda": lam, "sample_wm": sample_wm, "pdf_wm": pdf_wm},
        protocol=PROTOCOL,
    )
