"""examples/external/dielectric.py's model, gated in-process: it passes the ci audit, and each
--defect variant fails on its named check, run alone as the harness's kill tests run it (its
functions take one item in pure Python, batched by mfh.per_item: minutes, not seconds)."""
import pytest
from conftest import load_example

import mfh

SPEC = {"bsdf": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}


@pytest.mark.parametrize("defect, check", [(None, None), ("refraction_jacobian", "bsdf.chi2")])
def test_dielectric_py(defect, check):
    d = load_example("dielectric.py", *(["--defect", defect] if defect else []))
    report = mfh.audit_bsdf(eval=mfh.per_item(d.bsdf_eval), pdf=mfh.per_item(d.bsdf_pdf),
                            sample=mfh.per_item(d.bsdf_sample, "sample"), eta=d.ETA,
                            against=SPEC if check is None else None, checks=check and [check])
    if check is None:
        report.assert_pass()
    else:
        assert check in report.failed_checks, report
