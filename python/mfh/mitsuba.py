"""Audit any Mitsuba 3 BSDF (a built-in plugin or a Python ``mi.BSDF`` subclass) with mfh, in
the active variant: ``mfh.mitsuba.audit_bsdf(bsdf, profile="ci")``. Mitsuba is an optional
dependency (``pip install mitsuba``); this module imports it when called.

The mapping, done once here (checked against Mitsuba 3.9.1's source and against mfh's reference
BSDFs, tools/mitsuba_bsdf_child.py and docs/gate.md):

- Frame: a ``SurfaceInteraction3f`` with n = +z and ``sh_frame`` the identity; ``si.wi`` is
  mfh's ``wi`` (the camera side, as in Mitsuba). mfh's float64 inputs are rounded to the
  variant's precision on the way in; answers are widened on the way out.
- ``eval`` = Mitsuba's ``eval`` (f |cos theta_o|, as mfh's), ``pdf`` = Mitsuba's ``pdf``;
  ``sample``: u[0] -> ``sample1``, (u[1], u[2]) -> ``sample2`` (u kept below 1 in the
  variant's precision, as a renderer's samplers keep it); wo, pdf = ``bs.wo``, ``bs.pdf``,
  weight = Mitsuba's weight as returned (already divided by the pdf).
- Failed samples: a sample Mitsuba returns with pdf 0, weight 0 or a non-finite wo is mfh's
  failed sample (pdf 0), as ``mitsuba.chi2.BSDFAdapter`` counts it; a NaN answer is answered as
  0 and counted on stderr (mfh refuses NaN).
- Transport: ``transport="radiance"`` is ``mi.TransportMode.Radiance`` (Walter's eq 21 times
  (eta_i/eta_o)^2: mfh's "radiance"), ``"importance"`` is ``TransportMode.Importance``.
- Precision: single-precision variants (``scalar_rgb``, ``llvm_ad_rgb``, ...) are audited as
  float32 (``precision="f32"``), ``*_double`` variants as float64.
- eta: the plugin's ``eta`` parameter (``mi.traverse``) when it transmits (its flags have
  ``BSDFFlags.Transmission``); ``eta=`` overrides it. A BSDF with a delta lobe is refused
  (no density-based check resolves a delta).
- Lobes: all of them (``BSDFContext()``'s default type mask and component); eval is their sum
  and pdf their mixture density, as a renderer's MIS uses them.
- Spectra: eval and the weight are RGB (or mono); channel ``channel`` (default 0) is audited.
- Batches: llvm variants evaluate a whole batch as Dr.Jit arrays (one kernel a call); scalar
  variants, which have no arrays, one item at a time (slow: prefer an llvm variant).
"""
import re
import sys
import threading

import numpy as np

import mfh

__all__ = ["audit_bsdf", "adapt"]

_LOCK = threading.Lock()


def _mitsuba():
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        raise ImportError("mfh.mitsuba needs Mitsuba 3: pip install mitsuba (%s)" % e) from None
    try:
        variant = mi.variant()
    except Exception:  # noqa: BLE001 - older versions raise when no variant is set
        variant = None
    if not variant:
        raise RuntimeError("mfh.mitsuba: no Mitsuba variant is active: call "
                           "mi.set_variant('llvm_ad_rgb') (or 'scalar_rgb') first")
    return mi, dr, variant


class _Adapter:
    """A Mitsuba BSDF's eval, pdf and sample over numpy batches, in the active variant."""

    def __init__(self, mi, dr, variant, bsdf, transport, channel):
        if "spectral" in variant or "polarized" in variant:
            raise ValueError("mfh.mitsuba: variant %s: only rgb and mono variants are audited "
                             "(a spectral variant's channels are sampled wavelengths)" % variant)
        self.mi, self.dr, self.bsdf = mi, dr, bsdf
        self.vectorized = not variant.startswith("scalar")
        self.double = "double" in variant
        self.dtype = np.float64 if self.double else np.float32
        # The largest uniform below 1 in the variant's precision.
        self.u_max = self.dtype(1.0) - self.dtype(np.finfo(self.dtype).epsneg)
        mode = {"radiance": mi.TransportMode.Radiance,
                "importance": mi.TransportMode.Importance}[transport]
        self.ctx = mi.BSDFContext(mode)
        self.channel = channel
        self.nan_count = 0

    # --- conversions ---------------------------------------------------------------------

    def _vector(self, a):
        mi = self.mi
        a = np.asarray(a, dtype=self.dtype)
        if not self.vectorized:
            return mi.Vector3f(float(a[0]), float(a[1]), float(a[2]))
        return mi.Vector3f(*(mi.Float(np.ascontiguousarray(a[:, j])) for j in range(3)))

    def _interaction(self, wi):
        mi, dr = self.mi, self.dr
        si = dr.zeros(mi.SurfaceInteraction3f, len(wi)) if self.vectorized else \
            dr.zeros(mi.SurfaceInteraction3f)
        si.n = mi.Normal3f(0.0, 0.0, 1.0)
        si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0),
                                 mi.Vector3f(0, 0, 1))
        si.wi = self._vector(wi)
        return si

    def _channel(self, value):
        """Channel `channel` of a spectrum (or a Float) as float64 numpy."""
        a = np.asarray(value, dtype=np.float64)
        if self.vectorized:
            if a.ndim == 2:  # (channels, N)
                return a[self.channel if a.shape[0] > 1 else 0]
            return a
        return a.reshape(-1)[self.channel if a.size > 1 else 0:][:1]

    def _no_nan(self, a):
        bad = np.isnan(a)
        if bad.any():
            self.nan_count += int(bad.sum())
            print("mfh.mitsuba: %d NaN answers from Mitsuba answered as 0 (%d in all)"
                  % (int(bad.sum()), self.nan_count), file=sys.stderr)
            a = np.where(bad, 0.0, a)
        return a

    def _items(self, function, *arrays):
        """function on whole batches (llvm) or row by row (scalar), answers concatenated."""
        with _LOCK:
            if self.vectorized:
                return function(*arrays)
            rows = [function(*row) for row in zip(*arrays)]
            return tuple(np.concatenate(column) for column in zip(*rows))

    # --- Mitsuba calls ---------------------------------------------------------------------

    def _eval1(self, wi, wo):
        return (self._channel(self.bsdf.eval(self.ctx, self._interaction(wi), self._vector(wo))),)

    def _pdf1(self, wi, wo):
        pdf = self.bsdf.pdf(self.ctx, self._interaction(wi), self._vector(wo))
        return (np.asarray(pdf, dtype=np.float64).reshape(-1),)

    def _sample1(self, wi, u):
        mi = self.mi
        u = np.minimum(np.asarray(u, dtype=self.dtype), self.u_max)
        if self.vectorized:
            s1 = mi.Float(np.ascontiguousarray(u[:, 0]))
            s2 = mi.Point2f(mi.Float(np.ascontiguousarray(u[:, 1])),
                            mi.Float(np.ascontiguousarray(u[:, 2])))
        else:
            s1, s2 = float(u[0]), mi.Point2f(float(u[1]), float(u[2]))
        bs, weight = self.bsdf.sample(self.ctx, self._interaction(wi), s1, s2)
        wo = np.asarray(bs.wo, dtype=np.float64).reshape(3, -1).T
        return wo, np.asarray(bs.pdf, dtype=np.float64).reshape(-1), self._channel(weight)

    # --- mfh's three functions -------------------------------------------------------------

    def eval(self, wi, wo):
        return self._no_nan(self._items(self._eval1, wi, wo)[0])

    def pdf(self, wi, wo):
        return self._no_nan(self._items(self._pdf1, wi, wo)[0])

    def sample(self, wi, u):
        wo, pdf, weight = self._items(self._sample1, wi, u)
        pdf, weight = self._no_nan(pdf), self._no_nan(weight)
        failed = ~((pdf > 0.0) & (weight > 0.0) & np.isfinite(wo).all(axis=1))
        wo = np.where(failed[:, None], [0.0, 0.0, 1.0], wo)
        return wo, np.where(failed, 0.0, pdf), np.where(failed, 0.0, weight)


def _eta(mi, bsdf, eta):
    """The relative index: `eta` when given, else the plugin's `eta` when it transmits."""
    if eta is not None:
        return float(eta)
    if not mi.has_flag(bsdf.flags(), mi.BSDFFlags.Transmission):
        return None
    params = mi.traverse(bsdf)
    for key in ("eta", "eta.value"):
        if key in params:
            return float(np.asarray(params[key], dtype=np.float64).reshape(-1)[0])
    raise ValueError("mfh.mitsuba: the BSDF transmits but has no 'eta' parameter: give eta= "
                     "(eta_inside / eta_outside)")


def adapt(bsdf, transport="radiance", channel=0):
    """The three functions (eval, pdf, sample) over numpy batches that audit a Mitsuba BSDF in
    the active variant, with the mapping of this module's documentation."""
    mi, dr, variant = _mitsuba()
    if not isinstance(bsdf, mi.BSDF):
        raise TypeError("bsdf must be a mi.BSDF of the active variant (%s), not %s"
                        % (variant, type(bsdf).__name__))
    if mi.has_flag(bsdf.flags(), mi.BSDFFlags.Delta):
        raise ValueError("mfh.mitsuba: the BSDF has a delta lobe (flags %s): mfh's checks are "
                         "density-based and do not resolve a delta" % bsdf.flags())
    if transport not in ("radiance", "importance"):
        raise ValueError('transport = %r is not one of "radiance", "importance"' % (transport,))
    if not (isinstance(channel, int) and 0 <= channel < 3):
        raise ValueError("channel = %r is not 0, 1 or 2" % (channel,))
    return _Adapter(mi, dr, variant, bsdf, transport, channel)


def audit_bsdf(bsdf, profile="ci", transport="radiance", eta=None, channel=0, against=None,
               seed=None, name=None, checks=None, quiet=False, precision=None):
    """Audits a Mitsuba BSDF of the active variant with :func:`mfh.audit_bsdf`: the mapping
    of this module's documentation, the precision of the variant (f32 unless a ``_double``
    variant; ``precision=`` overrides), eta from the plugin (``eta=`` overrides), all lobes,
    channel ``channel`` of its spectrum. Returns a :class:`mfh.Report`."""
    mi, dr, variant = _mitsuba()
    model = adapt(bsdf, transport=transport, channel=channel)
    if precision is None:
        precision = "f64" if model.double else "f32"
    if name is None:
        plugin = bsdf.id() or type(bsdf).__name__
        if plugin in ("", "BSDF"):  # a built-in plugin: its to_string's class name
            plugin = re.split(r"[\[:\n]", str(bsdf), maxsplit=1)[0].strip() or "BSDF"
        name = "mitsuba %s %s" % (plugin, variant)
    return mfh.audit_bsdf(
        eval=model.eval, pdf=model.pdf, sample=model.sample, eta=_eta(mi, bsdf, eta),
        transport=transport, precision=precision, profile=profile, against=against, seed=seed,
        name=name, checks=checks, quiet=quiet)
