"""BSDFs and NDFs vectorized with numpy, audited in-process at the ci profile."""
import numpy as np
import pytest
from conftest import load_example
from numpy_dielectric import DEFECTS, Dielectric

import mfh

SPEC = {"bsdf": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}


def test_the_numpy_dielectric_passes_against_the_reference():
    model = Dielectric(alpha=0.3, eta=1.5)
    report = mfh.audit_bsdf(eval=model.eval, pdf=model.pdf, sample=model.sample, eta=model.eta,
                            against=SPEC, name="numpy dielectric")
    print(repr(report), "\ncalls, items:", report.calls)
    report.assert_pass()
    checks = {r["check"] for r in report.records}
    for want in ("bsdf.chi2", "bsdf.sample_consistency", "bsdf.failure_rate", "bsdf.albedo",
                 "bsdf.reciprocity", "bsdf.stability", "bsdf.against", "audit.precision"):
        assert want in checks, (want, sorted(checks))
    assert sum(r["check"] == "bsdf.chi2" for r in report.records) == 5


@pytest.mark.parametrize("defect", sorted(DEFECTS))
def test_each_numpy_defect_fails_its_named_check(defect):
    model = Dielectric(defect=defect)
    report = mfh.audit_bsdf(eval=model.eval, pdf=model.pdf, sample=model.sample, eta=model.eta,
                            checks=[DEFECTS[defect]])
    assert not report.passed and report.failed_checks == [DEFECTS[defect]], report


def test_the_ndf_it_is_built_on_is_compared_with_walters_formulas():
    model = Dielectric()
    ndf = {"d": model.d, "lambda_": model.lambda_, "masking": "height_correlated",
           "sampling": "visible_normals"}
    report = mfh.audit_bsdf(eval=model.eval, pdf=model.pdf, sample=model.sample, eta=model.eta,
                            ndf=ndf, checks=["bsdf.ndf_consistency"])
    assert {r["check"] for r in report.records} == {"bsdf.ndf_consistency", "audit.precision"}
    report.assert_pass()
    bad = Dielectric(defect="refraction_jacobian")
    report = mfh.audit_bsdf(eval=bad.eval, pdf=bad.pdf, sample=bad.sample, eta=bad.eta,
                            ndf=dict(ndf, d=bad.d, lambda_=bad.lambda_),
                            checks=["bsdf.ndf_consistency"])
    assert report.failed_checks == ["bsdf.ndf_consistency"], report


def test_float32_answers_are_accepted_and_judged_at_f32():
    model = Dielectric()

    def f32(f):
        return lambda *a: np.asarray(f(*a), dtype=np.float32)

    def sample(wi, u):
        return tuple(np.asarray(x, dtype=np.float32) for x in model.sample(wi, u))

    report = mfh.audit_bsdf(eval=f32(model.eval), pdf=f32(model.pdf), sample=sample,
                            eta=model.eta, precision="f32", checks=["bsdf.reciprocity"])
    report.assert_pass()
    assert {r["precision"] for r in report.records} == {"f32"}


def test_ggx_numpy_ndf_passes_and_a_wrong_normalization_fails():
    g = load_example("ggx_numpy.py")
    report = mfh.audit_ndf(d=g.d, lambda_=g.lam, sample_wm=g.sample_wm, pdf_wm=g.pdf_wm,
                           against={"family": "ggx", "alpha": 0.3}, name="ggx_numpy")
    print(repr(report), "\ncalls, items:", report.calls)
    report.assert_pass()
    report = mfh.audit_ndf(d=lambda m: 1.1 * g.d(m), name="ggx x 1.1")
    assert not report.passed
    assert any(c.startswith("normalization") for c in report.failed_checks), report
