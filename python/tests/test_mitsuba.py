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
