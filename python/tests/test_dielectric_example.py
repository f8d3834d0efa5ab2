"""examples/external/dielectric.py's model, gated in-process: it passes the ci audit, and each
--defect variant fails on its named check, run alone as the harness's kill tests run it (its
functions take one item in pure Python, batched by mfh.per_item: minutes, not seconds)."""
import os

import pytest
from conftest import load_example

import mfh

SPEC = {"bsdf": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}


# The whole ci audit of the pure-Python model took 1038 s at load ~20 (its single-item
# functions: ~2·10⁷ calls): the extensive tier, as the pure-Python audits of
# harness/tests/external_audit.rs. The defect, one named check, stays in every run.
WHOLE = pytest.param(None, None, marks=pytest.mark.skipif(
    os.environ.get("MFH_EXTENSIVE") != "1",
    reason="extensive tier (MFH_EXTENSIVE=1): the pure-Python ci audit takes minutes"))


@pytest.mark.parametrize("defect, check", [WHOLE, ("refraction_jacobian", "bsdf.chi2")])
def test_dielectric_py(defect, check):
    d = load_example("dielectric.py", *(["--defect", defect] if defect else []))
    report = mfh.audit_bsdf(eval=mfh.per_item(d.bsdf_eval), pdf=mfh.per_item(d.bsdf_pdf),
                            sample=mfh.per_item(d.bsdf_sample, "sample"), eta=d.ETA,
                            against=SPEC if check is None else None, checks=check and [check])
    if check is None:
        report.assert_pass()
    else:
        assert check in report.failed_checks, report
