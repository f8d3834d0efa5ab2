#!/usr/bin/env python3
"""DELIBERATELY WRONG: ggx.py (imported, not copied) with the Beckmann sampler's slope radius
rho^2 = -ln(1 - u2) in sample_wm (a copy-paste slip between two families). D, Lambda, pdf_wm and
the visible sampler are ggx.py's and right, so the samples do not follow the pdf: the check
`sampling.chi2` fails. Run by mfh:

    mfh audit-external --cmd "python3 examples/external/ggx_wrong_sampler.py" --profile ci

Options: those of ggx.py.
"""
import math

import ggx
from ggx import AX, AY, PI


def wrong_sample_wm(u):
    phi = 2.0 * PI * u[0]
    rho = math.sqrt(-math.log1p(-u[1]))  # WRONG: Beckmann's radius, GGX needs u2 / (1 - u2)
    px, py = AX * rho * math.cos(phi), AY * rho * math.sin(phi)
    n = math.sqrt(1.0 + px * px + py * py)
    return [-px / n, -py / n, 1.0 / n]


if __name__ == "__main__":
    ggx.main("ggx_wrong_sampler.py", wrong_sample_wm)
