"""Mitsuba 3 BSDFs audited in-process through mfh.mitsuba, in the llvm_ad_rgb variant (whole
batches as Dr.Jit arrays). Skipped, saying why, without Mitsuba or without an LLVM its JIT
runs on."""
import pytest
from conftest import mitsuba_llvm

import mfh


@pytest.fixture(scope="module")
def mi():
    return mitsuba_llvm()


def test_principled_passes(mi):
    bsdf = mi.load_dict({"type": "principled", "roughness": 0.4, "metallic": 0.3})
    report = mfh.mitsuba.audit_bsdf(bsdf)
    print(repr(report))
    report.assert_pass()


def diffuse_plugin(mi, divide_by_pdf=True):
    """A Lambertian mi.BSDF written in Python (as Mitsuba's documentation writes one); with
    divide_by_pdf False its sample weight is eval, not eval / pdf: the classic bug."""
    import drjit as dr

    class Diffuse(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.albedo = 0.7
            self.m_flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide
            self.m_components = [self.m_flags]

        def _value(self, si, wo):
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            active = (cos_i > 0) & (cos_o > 0)
            return active, self.albedo * dr.inv_pi * dr.maximum(cos_o, 0)

        def sample(self, ctx, si, sample1, sample2, active=True):
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = mi.warp.square_to_cosine_hemisphere(sample2)
            bs.pdf = mi.warp.square_to_cosine_hemisphere_pdf(bs.wo)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.DiffuseReflection)
            bs.sampled_component = 0
            ok, value = self._value(si, bs.wo)
            weight = value / bs.pdf if divide_by_pdf else value
            return bs, mi.Color3f(dr.select(ok & (bs.pdf > 0), weight, 0.0))

        def eval(self, ctx, si, wo, active=True):
            ok, value = self._value(si, wo)
            return mi.Color3f(dr.select(ok, value, 0.0))

        def pdf(self, ctx, si, wo, active=True):
            ok, _ = self._value(si, wo)
            return dr.select(ok, mi.warp.square_to_cosine_hemisphere_pdf(wo), 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def to_string(self):
            return "Diffuse[divide_by_pdf=%s]" % divide_by_pdf

    name = "mfh_test_diffuse_%s" % ("ok" if divide_by_pdf else "undivided")
    mi.register_bsdf(name, lambda props: Diffuse(props))
    return mi.load_dict({"type": name})


def test_a_python_diffuse_plugin_passes(mi):
    report = mfh.mitsuba.audit_bsdf(diffuse_plugin(mi), name="python diffuse")
    print(repr(report))
    report.assert_pass()


def test_the_plugin_whose_weight_is_not_divided_by_the_pdf_fails(mi):
    report = mfh.mitsuba.audit_bsdf(diffuse_plugin(mi, divide_by_pdf=False),
                                    name="python diffuse, weight not divided by the pdf")
    print(repr(report))
    assert "bsdf.sample_consistency" in report.failed_checks, report


def roughdielectric(mi, sample_visible):
    return mi.load_dict({"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3,
                         "int_ior": 1.5, "sample_visible": sample_visible})


def test_roughdielectric_passes(mi):
    report = mfh.mitsuba.audit_bsdf(roughdielectric(mi, True))
    print(repr(report), "\ncalls, items:", report.calls)
    report.assert_pass()
    assert sum(r["check"] == "bsdf.chi2" for r in report.records) == 5


def test_roughdielectric_without_visible_normals_has_weights_that_are_not_eval_over_pdf(mi):
    """Mitsuba 3.9.1's roughdielectric with sample_visible false samples m with alpha scaled
    by 1.2 - 0.2 sqrt|cos theta_i| (Walter's trick) and pdf() uses that scaled alpha too (the
    chi-square passes), but sample()'s weight is G |wi.m| / (|cos theta_i| cos theta_m), the
    weight of m drawn from the unscaled D: it lacks D(m) / D_scaled(m), so the weight is not
    eval / pdf except at normal incidence (scale 1), and the mean weight is not the albedo."""
    report = mfh.mitsuba.audit_bsdf(roughdielectric(mi, False))
    print(repr(report))
    assert "bsdf.sample_consistency" in report.failed_checks, report
    assert set(report.failed_checks) <= {"bsdf.sample_consistency", "bsdf.albedo"}, report
    consistency = {r["case"]["incidence"]: r for r in report.records
                   if r["check"] == "bsdf.sample_consistency"}
    assert consistency["normal"]["verdict"] == "pass"
    assert len(consistency) == 5, sorted(consistency)
    assert all(r["verdict"] == "fail" for i, r in consistency.items() if i != "normal"), report
