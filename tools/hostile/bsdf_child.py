#!/usr/bin/env python3
"""A hostile BSDF child for the before/after table of the trust work (tools/hostile/run.sh).

The float64 numpy rough dielectric of python/tests/numpy_dielectric.py (Walter 2007, GGX,
visible-normal sampling, radiance transport), served through examples/external/mfh_protocol.py,
with one planted defect chosen by the options:

    --eta E            eta inside / eta outside (default 1.5)
    --alpha A          GGX roughness (default 0.3)
    --loss F           a sample fails (pdf 0) when frac(64 u0) < F: a silent loss of F of the
                       samples, independent of the direction drawn (as check/bsdf/corner_tests.rs)
    --scale S          eval and sample weight S times too large (pdf unchanged): an energy gain
    --precision P      declare "precision": P in describe (the answers stay float64)
    --weight-error E   sample weight (1 + E) times too large
    --huge-eval        eval answers 1e308 wherever the model's eval is not 0

stdout is the protocol channel: log to stderr only.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "python", "tests"))
sys.path.insert(0, os.path.join(ROOT, "examples", "external"))

import numpy as np  # noqa: E402

import mfh_protocol  # noqa: E402
from numpy_dielectric import Dielectric  # noqa: E402

ARGS = sys.argv[1:]
FLAGS = {a for a in ARGS if a == "--huge-eval"}
OPTS = dict(zip([a for a in ARGS if a not in FLAGS][::2], [a for a in ARGS if a not in FLAGS][1::2]))
ETA = float(OPTS.get("--eta", 1.5))
ALPHA = float(OPTS.get("--alpha", 0.3))
LOSS = float(OPTS.get("--loss", 0.0))
SCALE = float(OPTS.get("--scale", 1.0))
PRECISION = OPTS.get("--precision")
WEIGHT_ERROR = float(OPTS.get("--weight-error", 0.0))
HUGE = "--huge-eval" in FLAGS

model = Dielectric(alpha=ALPHA, eta=ETA)


def bsdf_eval(wi, wo):
    value = model.eval(wi, wo)
    if HUGE:
        return np.where(value != 0.0, 1e308, 0.0)
    return value * SCALE


def bsdf_pdf(wi, wo):
    return model.pdf(wi, wo)


def bsdf_sample(wi, u):
    wo, pdf, weight = model.sample(wi, u)
    weight = weight * SCALE * (1.0 + WEIGHT_ERROR)
    if LOSS > 0.0:
        lost = np.modf(u[:, 0] * 64.0)[0] < LOSS
        pdf = np.where(lost, 0.0, pdf)
        weight = np.where(lost, 0.0, weight)
    return wo, pdf, weight


extra = {"eta": ETA, "transport": "radiance"}
if PRECISION:
    extra["precision"] = PRECISION
mfh_protocol.serve(
    "hostile bsdf_child.py " + " ".join(ARGS),
    {"ndf": {"family": "ggx", "alpha": ALPHA}, "eta": ETA, "loss": LOSS, "scale": SCALE,
     "weight_error": WEIGHT_ERROR, "huge_eval": HUGE},
    {"bsdf_eval": bsdf_eval, "bsdf_pdf": bsdf_pdf, "bsdf_sample": bsdf_sample},
    numpy=True,
    extra=extra,
)
