#!/usr/bin/env python3
"""Mitsuba 3's own `roughdielectric` and `roughconductor` plugins (float32) as an mfh external
protocol child (docs/external-protocol.md), to audit Mitsuba's BSDF with mfh by hand. A
cross-check tool: no test or CI runs it. Needs `pip install mitsuba` (3.x) and numpy; its
llvm variant needs Debian's libllvm19 and, where Dr.Jit does not find it,
DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 (an older LLVM aborts in its JIT).
Measured results: docs/gate.md, "Float32 BSDFs".

    mfh audit-external --profile ci --cmd "python3 tools/mitsuba_bsdf_child.py \\
        --bsdf roughdielectric --distribution ggx --alpha 0.3 --int-ior 1.5"
    mfh audit-external --profile ci --cmd "python3 tools/mitsuba_bsdf_child.py \\
        --bsdf roughconductor --distribution ggx --alpha 0.3 --material Au"

Options: --bsdf roughdielectric|roughconductor; --distribution ggx|beckmann (default ggx);
--alpha A (default 0.3); --sample-visible true|false (default true); roughdielectric:
--int-ior (default 1.5), --ext-ior (default 1.0); roughconductor: --material NAME (Mitsuba's
table, e.g. Au, Cu) or --eta N --k K (Mitsuba's defaults when neither: eta 0, k 1);
--variant V (default llvm_ad_rgb, whole batches as Dr.Jit arrays, falling back to scalar_rgb,
one item at a time; `llvm_rgb`, absent from the pip wheel, means llvm_ad_rgb there);
--declare-precision f32|f64 (default f32: what the describe answer says); --protocol 1|2.
The describe answer's "parameters" carry "mfh_spec", the reference BSDF that should equal
this one, for `--against` (Mitsuba's masking is mfh's "uncorrelated", see below).

Convention mapping (mfh: reference/src/bsdf/mod.rs):
- Frame: a SurfaceInteraction3f with n = +z, sh_frame the identity, si.wi = mfh's wi (the
  camera side, as in Mitsuba); BSDFContext() in radiance mode. mfh's f64 inputs are rounded to
  float32 on the way in (u kept below 1, as a renderer's samplers are), answers widened out.
- eval = Mitsuba's eval (f |cos θo|, as mfh); pdf = Mitsuba's pdf; sample: u[0] -> sample1,
  (u[1], u[2]) -> sample2; wo, pdf = bs.wo, bs.pdf, weight = Mitsuba's weight as returned.
  A sample Mitsuba returns with weight 0 (e.g. a reflection below the horizon: roughdielectric
  does not mask it, smith_g1(wo, m) zeroes the weight) or pdf 0 is answered as mfh's failed
  sample (pdf 0, weight 0), as mitsuba.chi2.BSDFAdapter counts it. A NaN from Mitsuba is
  answered as 0 and counted on stderr (mfh refuses NaN answers).
- Spectra: eval and the weight are RGB; channel 0 is answered. The dielectric's three channels
  are equal; the conductor's differ when its index is spectral (--material): channel 0 is
  red, and "mfh_spec" carries the channel-0 n and k.
- eta = int_ior / ext_ior as Mitsuba stores it (float32).

What Mitsuba 3.9.1 does (its source; checked against `mfh eval`, numbers below):
- Transport: in radiance mode roughdielectric multiplies Walter's eq 21 by 1/η² with
  η = η_o/η_i the relative index in wi -> wo's direction (its `inv_eta` squared), i.e. by
  (η_i/η_o)²: 1/2.25 from outside, 2.25 from inside at int_ior 1.5. That is mfh's
  "radiance" (Transport::Radiance) exactly; its sampling weight carries the same eta_ti².
- Masking: G = smith_g1(wi, m) smith_g1(wo, m) in both lobes, each 0 when v·m and v_z differ
  in sign: mfh's "uncorrelated". GGX's G1 is exact; Beckmann's is a rational approximation
  (Walter's, < 0.35 % relative), so against mfh's exact Beckmann only to ~3e-3.
- Sides: roughdielectric evaluates and samples wi from either side (η inverted, m and the
  sampling at wi⁺); roughconductor is one-sided: eval, pdf and sample are 0 for wi_z <= 0.
- Sampling: visible normals (Heitz & d'Eon 2014, slopes) maps u to m differently from mfh's
  reference (Heitz 2018), so the sampled directions of --against differ for the same u while
  the densities agree; with sample_visible false the dielectric samples with α scaled by
  1.2 - 0.2 sqrt|cos θi| (Walter's trick), which no mfh spec names.

stdout is the protocol channel: log to stderr only.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples",
                                "external"))
import mfh_protocol  # noqa: E402 (the repository's protocol helper, beside the examples)

# The largest float32 below 1: a u < 1 in f64 may round up to 1.0 in float32.
U_MAX = np.float32(1.0) - np.float32(2.0 ** -24)


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--bsdf", required=True, choices=["roughdielectric", "roughconductor"])
    p.add_argument("--distribution", default="ggx", choices=["ggx", "beckmann"])
    p.add_argument("--alpha", type=float, default=0.3)
    p.add_argument("--sample-visible", default="true", choices=["true", "false"])
    p.add_argument("--int-ior", type=float, default=1.5)
    p.add_argument("--ext-ior", type=float, default=1.0)
    p.add_argument("--material")
    p.add_argument("--eta", type=float)
    p.add_argument("--k", type=float)
    p.add_argument("--variant")
    p.add_argument("--declare-precision", default="f32", choices=["f32", "f64"])
    p.add_argument("--protocol", type=int, default=2, choices=list(mfh_protocol.VERSIONS))
    return p.parse_args()


def load_mitsuba(requested):
    """(mitsuba, drjit, variant, vectorized): the requested variant, else llvm_ad_rgb, else
    scalar_rgb (an llvm variant whose JIT cannot start, e.g. without libllvm, is skipped)."""
    import drjit as dr
    import mitsuba as mi

    if requested == "llvm_rgb" and "llvm_rgb" not in mi.variants():
        requested = "llvm_ad_rgb"
    candidates = [requested] if requested else ["llvm_ad_rgb", "scalar_rgb"]
    for variant in candidates:
        try:
            mi.set_variant(variant)
            vectorized = not variant.startswith("scalar")
            if vectorized:
                dr.eval(mi.Float([1.0, 2.0]) + 1.0)  # starts the JIT: fails without LLVM
            return mi, dr, variant, vectorized
        except Exception as e:  # noqa: BLE001 - any failure: try the next variant
            print("mitsuba_bsdf_child: variant %s unavailable (%s)" % (variant, e),
                  file=sys.stderr)
    sys.exit("mitsuba_bsdf_child: no usable Mitsuba variant among %s" % candidates)


def plugin_properties(args):
    """The Mitsuba plugin's properties (a load_dict dictionary)."""
    props = {"type": args.bsdf, "distribution": args.distribution, "alpha": args.alpha,
             "sample_visible": args.sample_visible == "true"}
    if args.bsdf == "roughdielectric":
        props.update(int_ior=args.int_ior, ext_ior=args.ext_ior)
    elif args.eta is not None or args.k is not None:
        props.update(eta=args.eta if args.eta is not None else 0.0,
                     k=args.k if args.k is not None else 1.0)
    elif args.material:
        props["material"] = args.material
    return props


class MitsubaBsdf:
    """A loaded plugin and the three protocol functions over numpy batches: (n, 3) arrays of
    f64 in, f64 arrays out (computed in float32)."""

    def __init__(self, mi, dr, props, vectorized):
        self.mi, self.dr, self.vectorized = mi, dr, vectorized
        self.bsdf = mi.load_dict(props)
        self.ctx = mi.BSDFContext(mi.TransportMode.Radiance)
        self.nan_count = 0

    def first(self, value):
        """Channel 0 of a spectrum, or a Float, as f64 numpy."""
        a = np.array(value, dtype=np.float64)
        if self.vectorized:
            return a[0] if a.ndim == 2 else a
        return a.reshape(-1)[:1]  # scalar: a Color3f's three numbers or one float -> one

    def vector(self, a):
        """An (n, 3) array (or one row in scalar mode) as a Vector3f of float32."""
        mi = self.mi
        a = np.asarray(a, dtype=np.float32)
        if not self.vectorized:
            return mi.Vector3f(float(a[0]), float(a[1]), float(a[2]))
        return mi.Vector3f(*(mi.Float(np.ascontiguousarray(a[:, j])) for j in range(3)))

    def interaction(self, wi):
        mi, dr = self.mi, self.dr
        n = 1 if not self.vectorized else len(wi)
        si = dr.zeros(mi.SurfaceInteraction3f, n) if self.vectorized else \
            dr.zeros(mi.SurfaceInteraction3f)
        si.n = mi.Normal3f(0.0, 0.0, 1.0)
        si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
        si.wi = self.vector(wi)
        return si

    def per_item(self, function, *arrays):
        """function over whole batches (llvm) or row by row (scalar), answers concatenated."""
        if self.vectorized:
            return function(*arrays)
        rows = [function(*row) for row in zip(*arrays)]
        return tuple(np.concatenate(column) for column in zip(*rows))

    def no_nan(self, a):
        bad = np.isnan(a)
        if bad.any():
            self.nan_count += int(bad.sum())
            print("mitsuba_bsdf_child: %d NaN answers from Mitsuba answered as 0 (%d in all)"
                  % (int(bad.sum()), self.nan_count), file=sys.stderr)
            a = np.where(bad, 0.0, a)
        return a

    def _eval(self, wi, wo):
        value = self.bsdf.eval(self.ctx, self.interaction(wi), self.vector(wo))
        return (self.first(value),)

    def _pdf(self, wi, wo):
        pdf = self.bsdf.pdf(self.ctx, self.interaction(wi), self.vector(wo))
        return (self.first(pdf),)

    def _sample(self, wi, u):
        mi = self.mi
        u = np.minimum(np.asarray(u, dtype=np.float32), U_MAX)
        if self.vectorized:
            s1 = mi.Float(np.ascontiguousarray(u[:, 0]))
            s2 = mi.Point2f(mi.Float(np.ascontiguousarray(u[:, 1])),
                            mi.Float(np.ascontiguousarray(u[:, 2])))
        else:
            s1, s2 = float(u[0]), mi.Point2f(float(u[1]), float(u[2]))
        bs, weight = self.bsdf.sample(self.ctx, self.interaction(wi), s1, s2)
        wo = np.array(bs.wo, dtype=np.float64).reshape(3, -1).T
        return wo, self.first(bs.pdf), self.first(weight)

    def bsdf_eval(self, wi, wo):
        return self.no_nan(self.per_item(self._eval, wi, wo)[0])

    def bsdf_pdf(self, wi, wo):
        return self.no_nan(self.per_item(self._pdf, wi, wo)[0])

    def bsdf_sample(self, wi, u):
        wo, pdf, weight = self.per_item(self._sample, wi, u)
        pdf, weight = self.no_nan(pdf), self.no_nan(weight)
        failed = ~((pdf > 0.0) & (weight > 0.0) & np.isfinite(wo).all(axis=1))
        wo = np.where(failed[:, None], [0.0, 0.0, 1.0], wo)
        return wo, np.where(failed, 0.0, pdf), np.where(failed, 0.0, weight)


def reference_spec(args, mi, plugin):
    """The mfh reference BSDF spec that names the same BSDF (channel 0 of a spectral index)."""
    params = mi.traverse(plugin)
    spec = {"ndf": {"family": args.distribution, "alpha": args.alpha},
            "masking": "uncorrelated",
            "sampling": "visible_normals" if args.sample_visible == "true" else "normals"}
    if args.bsdf == "roughdielectric":
        eta = float(np.array(params["eta"], dtype=np.float64).reshape(-1)[0])
        spec.update(bsdf="dielectric", eta=eta, transport="radiance")
    else:
        n = float(np.array(params["eta.value"], dtype=np.float64).reshape(-1)[0])
        k = float(np.array(params["k.value"], dtype=np.float64).reshape(-1)[0])
        spec.update(bsdf="conductor", n=n, k=k, fresnel="exact")
    return spec


def main():
    args = parse_args()
    mi, dr, variant, vectorized = load_mitsuba(args.variant)
    props = plugin_properties(args)
    model = MitsubaBsdf(mi, dr, props, vectorized)
    spec = reference_spec(args, mi, model.bsdf)
    extra = {"transport": "radiance", "precision": args.declare_precision}
    if args.bsdf == "roughdielectric":
        extra["eta"] = spec["eta"]
    print("mitsuba_bsdf_child: mitsuba %s %s, %s, answering channel 0" % (
        mi.__version__, variant, props), file=sys.stderr)
    parameters = {"mitsuba": mi.__version__, "variant": variant, "plugin": props,
                  "channel": 0, "mfh_spec": spec}
    functions = {"bsdf_eval": model.bsdf_eval, "bsdf_pdf": model.bsdf_pdf,
                 "bsdf_sample": model.bsdf_sample}
    mfh_protocol.serve("mitsuba " + args.bsdf, parameters, functions, protocol=args.protocol,
                       numpy=True, extra=extra)


if __name__ == "__main__":
    main()
