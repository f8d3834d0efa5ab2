"""mfh in Python: audit a BSDF or an NDF written in Python (numpy, or Mitsuba through
:mod:`mfh.mitsuba`) with the mfh harness, in-process: the harness calls your functions on numpy
arrays in batches, from its worker threads, and returns the report the ``mfh`` CLI writes.

    import mfh
    report = mfh.audit_bsdf(eval=my_eval, pdf=my_pdf, sample=my_sample, eta=1.5)
    report.assert_pass()

Conventions (those of the Rust ``Bsdf`` trait and of the external protocol, docs/python.md):
local shading frame, macro-normal +z pointing outside; ``wi`` and ``wo`` unit vectors pointing
away from the surface, either hemisphere, ``wi`` the camera side; ``eval`` = f(wi, wo) |wo_z|;
``pdf`` the solid-angle density of the ``wo`` that ``sample`` returns; a failed sample answers
pdf 0 (and weight 0); ``weight`` = eval / pdf; NaN is never an answer.
"""
import os
import sys

from . import _mfh
from ._report import Report, per_item

__all__ = ["audit_bsdf", "audit_ndf", "Report", "per_item", "DEFAULT_SEED"]
__version__ = _mfh.MFH_VERSION

#: The audit seed when neither ``seed=`` nor ``MFH_SEED`` gives one.
DEFAULT_SEED = _mfh.DEFAULT_SEED

_PROFILES = ("ci", "quick", "standard", "thorough")


def _callable(field, value, required=True):
    if value is None and not required:
        return None
    if not callable(value):
        raise TypeError("%s must be a callable, not %s" % (field, type(value).__name__))
    return value


def _seed(seed):
    """The audit seed: seed=, else MFH_SEED, else DEFAULT_SEED (a bad one names its source)."""
    if seed is not None:
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 64:
            raise ValueError("seed = %r is not a seed (an integer in 0..=%d)" % (seed, 2 ** 64 - 1))
        return seed
    text = os.environ.get("MFH_SEED")
    if text is None:
        return DEFAULT_SEED
    try:
        value = int(text.strip())
    except ValueError:
        value = -1
    if not 0 <= value < 2 ** 64:
        raise ValueError("MFH_SEED = %r is not a seed (an integer in 0..=%d)" % (text, 2 ** 64 - 1))
    return value


def _against(against):
    if against is None or isinstance(against, str):
        return against
    if isinstance(against, dict):
        import json
        return json.dumps(against)
    raise TypeError("against must be a reference spec as a dict or a JSON string, not %s"
                    % type(against).__name__)


def _checks(checks):
    if checks is None:
        return None
    if isinstance(checks, str):
        checks = [checks]
    checks = list(checks)
    if not checks or not all(isinstance(c, str) for c in checks):
        raise TypeError("checks must be check ids (e.g. ['bsdf.chi2']), not %r" % (checks,))
    return checks


def _name(name, function):
    if name is not None:
        if not isinstance(name, str):
            raise TypeError("name must be a string, not %s" % type(name).__name__)
        return name
    module = getattr(function, "__module__", None) or ""
    qualname = getattr(function, "__qualname__", None) or type(function).__name__
    return ("%s.%s" % (module, qualname)).lstrip(".")


def _command(function, name, profile, seed):
    """The line that reproduces the run: the pytest test it runs in, when it runs in one."""
    test = os.environ.get("PYTEST_CURRENT_TEST")
    if test:
        return "MFH_SEED=%d python -m pytest '%s'" % (seed, test.rsplit(" (", 1)[0])
    script = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "python"
    return "MFH_SEED=%d python %s  # mfh.%s(%s, profile=%r)" % (seed, script, function, name,
                                                              profile)


def _common(profile, precision, quiet):
    if profile not in _PROFILES:
        raise ValueError("profile = %r is not one of %s" % (profile, ", ".join(_PROFILES)))
    if precision not in ("f64", "f32"):
        raise ValueError('precision = %r is not one of "f64", "f32"' % (precision,))
    if not isinstance(quiet, bool):
        raise TypeError("quiet must be True or False")


def audit_bsdf(eval, pdf, sample, eta=None, transport="radiance", precision="f64",
               profile="ci", against=None, seed=None, ndf=None, name=None, checks=None,
               quiet=False):
    """Audits a whole BSDF given as three functions over numpy arrays, in-process.

    - ``eval(wi, wo)``: wi, wo of shape (N, 3) -> (N,): f(wi, wo) |wo_z|.
    - ``pdf(wi, wo)``: (N, 3), (N, 3) -> (N,): the solid-angle density of ``sample``'s wo.
    - ``sample(wi, u)``: wi (N, 3) (one incidence repeated), u (N, 3) uniforms in [0, 1)
      (u[:, 0] chooses the lobe, u[:, 1:] the microfacet normal) -> ``(wo, pdf, weight)`` of
      shapes (N, 3), (N,), (N,); a failed sample has pdf 0 (and weight 0, any finite wo).
    - ``eta``: eta_inside / eta_outside of a transmitting BSDF (None: reflection only).
    - ``transport``: ``"radiance"`` (pbrt-v4, Mitsuba 3) or ``"importance"``.
    - ``precision``: ``"f64"``, or ``"f32"`` for a float32 implementation (inputs stay
      float64; answers may be float32 arrays).
    - ``profile``: ``"ci"`` (default), ``"quick"``, ``"standard"``, ``"thorough"``.
    - ``against``: a reference BSDF spec (dict or JSON), e.g.
      ``{"bsdf": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}``:
      eval, pdf and the sampled directions compared value by value (``bsdf.against``).
    - ``seed``: the audit seed (default ``MFH_SEED``, else :data:`DEFAULT_SEED`).
    - ``ndf``: the NDF the BSDF is built on, a dict ``{"d": f, "lambda_": g}`` with optional
      ``"masking"`` (``"uncorrelated"`` | ``"height_correlated"``, the BSDF's G2 form) and
      ``"sampling": "visible_normals"`` (it samples that NDF's visible normals):
      ``bsdf.ndf_consistency`` compares the BSDF with Walter's eq 20 / 21 built from it.
    - ``name``: the model's name in the records (default: eval's module and name).
    - ``checks``: run only these check ids (e.g. ``["bsdf.chi2"]``), judged as in the whole
      audit (same seeds, the whole plan's Sidak level), as a shard would run them.
    - ``quiet``: no progress on stderr.

    Returns a :class:`Report`. The functions are called from the harness's threads (the GIL is
    taken for each call and released between calls); Ctrl-C stops the audit and raises
    ``KeyboardInterrupt``. An exception, an answer of the wrong shape or a NaN stops the calls
    and becomes a failing ``python.call`` record.
    """
    _callable("eval", eval)
    _callable("pdf", pdf)
    _callable("sample", sample)
    _common(profile, precision, quiet)
    if eta is not None:
        eta = float(eta)
    if transport not in ("radiance", "importance"):
        raise ValueError('transport = %r is not one of "radiance", "importance"' % (transport,))
    ndf_d = ndf_lambda = ndf_masking = None
    ndf_visible = False
    if ndf is not None:
        if not isinstance(ndf, dict):
            raise TypeError('ndf must be a dict {"d": f, "lambda_": g, ...}, not %s'
                            % type(ndf).__name__)
        unknown = set(ndf) - {"d", "lambda_", "masking", "sampling"}
        if unknown:
            raise ValueError("ndf: unknown keys %s (known: d, lambda_, masking, sampling)"
                             % sorted(unknown))
        ndf_d = _callable('ndf["d"]', ndf.get("d"))
        ndf_lambda = _callable('ndf["lambda_"]', ndf.get("lambda_"))
        ndf_masking = ndf.get("masking")
        sampling = ndf.get("sampling")
        if sampling not in (None, "visible_normals"):
            raise ValueError('ndf["sampling"] = %r: only "visible_normals" is declared '
                             '(absent: the pdf is not compared)' % (sampling,))
        ndf_visible = sampling == "visible_normals"
    seed = _seed(seed)
    name = _name(name, eval)
    return Report(_mfh.audit_bsdf(
        eval, pdf, sample, eta, transport, precision, profile, _against(against), seed, name,
        _checks(checks), quiet, _command("audit_bsdf", name, profile, seed), ndf_d,
        ndf_lambda, ndf_masking, ndf_visible))


def audit_ndf(d, lambda_=None, sample_wm=None, pdf_wm=None, sample_wm_visible=None,
              pdf_wm_visible=None, precision="f64", profile="ci", against=None, seed=None,
              name=None, checks=None, quiet=False, masking=None, sampling=None, theta_max=None):
    """Audits a normal distribution function given as functions over numpy arrays: the
    capabilities are the functions given, nothing else to declare.

    - ``d(m)``: (N, 3) -> (N,): D(m), 0 below the horizon; normalized so that
      the integral of D(m) m_z over the hemisphere is 1. Required.
    - ``lambda_(w)``: (N, 3) -> (N,): Smith Lambda(w) (Lambda(-w) = -1 - Lambda(w) below).
    - ``sample_wm(u)``: u (N, 2) -> (N, 3): normals distributed as D(m) m_z;
      ``pdf_wm(m)``: (N, 3) -> (N,) (default D(m) m_z).
    - ``sample_wm_visible(wi, u)``: (N, 3), (N, 2) -> (N, 3): visible normals (needs
      ``lambda_``); ``pdf_wm_visible(wi, m)`` (default G1(wi) <wi.m>+ D(m) / wi_z).
    - ``masking``: the renderer's G2 form (``"uncorrelated"``, ``"height_correlated"``,
      ``"none"``; default: both forms checked when ``lambda_`` is given); ``sampling``
      (``"normals"``, ``"visible_normals"``, ``"none"``; default: what is given);
      ``theta_max``: the largest incidence the renderer evaluates (radians, default pi/2).
    - ``against``: a reference NDF spec, e.g. ``{"family": "ggx", "alpha": 0.3}``.
    - ``precision``, ``profile``, ``seed``, ``name``, ``checks``, ``quiet``: as for
      :func:`audit_bsdf`.
    """
    _callable("d", d)
    lambda_ = _callable("lambda_", lambda_, required=False)
    sample_wm = _callable("sample_wm", sample_wm, required=False)
    pdf_wm = _callable("pdf_wm", pdf_wm, required=False)
    sample_wm_visible = _callable("sample_wm_visible", sample_wm_visible, required=False)
    pdf_wm_visible = _callable("pdf_wm_visible", pdf_wm_visible, required=False)
    if pdf_wm is not None and sample_wm is None:
        raise ValueError("pdf_wm is given without sample_wm (it is the density of sample_wm)")
    if (sample_wm_visible is not None or pdf_wm_visible is not None) and lambda_ is None:
        raise ValueError("sample_wm_visible / pdf_wm_visible need lambda_ (the visible-normal "
                         "density is G1(wi) <wi.m>+ D(m) / wi_z)")
    if pdf_wm_visible is not None and sample_wm_visible is None:
        raise ValueError("pdf_wm_visible is given without sample_wm_visible")
    _common(profile, precision, quiet)
    if theta_max is not None:
        theta_max = float(theta_max)
    seed = _seed(seed)
    name = _name(name, d)
    return Report(_mfh.audit_ndf(
        d, lambda_, sample_wm, pdf_wm, sample_wm_visible, pdf_wm_visible, precision, profile,
        _against(against), seed, name, _checks(checks), quiet,
        _command("audit_ndf", name, profile, seed), masking, sampling, theta_max))


# mfh.mitsuba imports Mitsuba only when called: importing it here costs nothing.
from . import mitsuba  # noqa: E402,F401
