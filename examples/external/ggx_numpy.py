#!/usr/bin/env python3
"""A GGX microfacet model speaking mfh's external protocol (version 2, or 1 with --protocol 1;
the protocol loop is mfh_protocol.py beside this file), vectorized with numpy: each batch is one
array operation, and in version 2 each array crosses the pipe as base64 of float64, decoded by
np.frombuffer. Run by mfh:

    mfh audit-external --cmd "python3 examples/external/ggx_numpy.py" --profile ci \
        --against '{"family":"ggx","alpha_x":0.3,"alpha_y":0.3}'

Options: --alpha A or --alpha-x AX --alpha-y AY (default 0.3), --protocol 1|2. Log to stderr
only.
"""
import mfh_protocol
import numpy as np

AX, AY, PROTOCOL = mfh_protocol.options()


def d(m):
    x, y, z = m[:, 0], m[:, 1], m[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        z2 = z * z
        s2 = ((x / AX) ** 2 + (y / AY) ** 2) / z2
        v = 1.0 / (np.pi * AX * AY * z2 * z2 * (1.0 + s2) ** 2)
    return np.where(z > 0.0, v, 0.0)


def lam_upper(x, y, z):
    t2 = (AX * x) ** 2 + (AY * y) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_a2 = t2 / (z * z)
        v = inv_a2 / (2.0 * (1.0 + np.sqrt(1.0 + inv_a2)))
    v = np.where(z == 0.0, np.inf, v)
    return np.where(t2 == 0.0, 0.0, v)


def lam(w):
    x, y, z = w[:, 0], w[:, 1], w[:, 2]
    up = lam_upper(np.abs(x), np.abs(y), np.abs(z))
    return np.where(z < 0.0, -1.0 - up, up)


def sample_wm(u):
    phi = 2.0 * np.pi * u[:, 0]
    rho = np.sqrt(u[:, 1] / (1.0 - u[:, 1]))
    px, py = AX * rho * np.cos(phi), AY * rho * np.sin(phi)
    n = np.sqrt(1.0 + px * px + py * py)
    return np.stack([-px / n, -py / n, 1.0 / n], axis=1)


def pdf_wm(m):
    return np.where(m[:, 2] > 0.0, d(m) * m[:, 2], 0.0)


if __name__ == "__main__":
    mfh_protocol.serve(
        "ggx_numpy.py",
        {"family": "ggx", "alpha_x": AX, "alpha_y": AY},
        {"d": d, "lambda": lam, "sample_wm": sample_wm, "pdf_wm": pdf_wm},
        protocol=PROTOCOL,
        numpy=True,
    )
