#!/usr/bin/env python3
"""A hostile NDF child for tools/hostile/run.sh: a D that is expensive for the oracles to
integrate, served through examples/external/mfh_protocol.py (numpy, capabilities d and lambda).

    --kind tabulated    GGX alpha 0.3's D tabulated at 256 polar angles in [0, pi/2] and
                        interpolated linearly in theta (a renderer's measured-NDF table: a kink
                        at every node)
    --kind oscillating  GGX alpha 0.3's D times (1 + 0.5 sin(200 theta)) (50 ripples)

Both answer GGX alpha 0.3's closed-form Lambda, so the Lambda records compare it with the
quadrature of their own D: the point is how long each record takes, not its verdict.
stdout is the protocol channel: log to stderr only.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "examples", "external"))

import numpy as np  # noqa: E402

import mfh_protocol  # noqa: E402

OPTS = dict(zip(sys.argv[1::2], sys.argv[2::2]))
KIND = OPTS.get("--kind", "tabulated")
if KIND not in ("tabulated", "oscillating"):
    sys.exit("--kind must be tabulated or oscillating")
A2 = 0.3 * 0.3
NODES = np.linspace(0.0, np.pi / 2, 256)


def ggx(theta):
    c = np.cos(theta)
    t2 = np.tan(theta) ** 2
    with np.errstate(all="ignore"):
        d = 1.0 / (np.pi * A2 * c**4 * (1.0 + t2 / A2) ** 2)
    return np.where(c > 0.0, d, 0.0)


TABLE = ggx(NODES)


def d(m):
    z = np.clip(m[:, 2], -1.0, 1.0)
    theta = np.arccos(z)
    if KIND == "tabulated":
        value = np.interp(theta, NODES, TABLE, right=0.0)
    else:
        value = ggx(theta) * (1.0 + 0.5 * np.sin(200.0 * theta))
    return np.where(z > 0.0, value, 0.0)


def lambda_(w):
    x, y, z = w[:, 0], w[:, 1], w[:, 2]
    with np.errstate(all="ignore"):
        t = A2 * (x * x + y * y) / (z * z)
        up = np.where(t == 0.0, 0.0, t / (2.0 * (1.0 + np.sqrt(1.0 + t))))
    up = np.where(z == 0.0, np.where(x * x + y * y > 0.0, np.inf, 0.0), up)
    return np.where(z < 0.0, -1.0 - up, up)


mfh_protocol.serve("hostile ndf_child.py --kind " + KIND, {"kind": KIND, "alpha": 0.3},
                   {"d": d, "lambda": lambda_}, numpy=True)
