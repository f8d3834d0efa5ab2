"""Shared helpers of the mfh Python tests: the repository's examples, and Mitsuba's variant
(probed in a child process: an LLVM older than Dr.Jit needs aborts the process in its JIT)."""
import importlib.util
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "..", "examples", "external")
sys.path.insert(0, HERE)


def load_example(file, *argv):
    """examples/external/<file> as a fresh module, its options (e.g. --defect) read from argv
    at import as on its command line."""
    if EXAMPLES not in sys.path:
        sys.path.insert(0, EXAMPLES)  # its `import mfh_protocol`
    saved, sys.argv = sys.argv, [file, *argv]
    try:
        name = file[:-3] + "".join("_" + a.strip("-") for a in argv)
        spec = importlib.util.spec_from_file_location(name, os.path.join(EXAMPLES, file))
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    finally:
        sys.argv = saved


_PROBE = """
import mitsuba as mi, drjit as dr
mi.set_variant("llvm_ad_rgb")
b = mi.load_dict({"type": "roughdielectric", "alpha": 0.3})
si = dr.zeros(mi.SurfaceInteraction3f, 2)
si.n = mi.Normal3f(0, 0, 1); si.sh_frame = mi.Frame3f(si.n); si.wi = mi.Vector3f(0.6, 0, 0.8)
dr.eval(b.eval(mi.BSDFContext(), si, mi.Vector3f(-0.6, 0, 0.8)))
"""

_variant = []


def mitsuba_llvm():
    """The mitsuba module with llvm_ad_rgb set, or a skip that says why."""
    if not _variant:
        try:
            import mitsuba  # noqa: F401
        except ImportError as e:
            _variant.append(("skip", "Mitsuba is not installed (pip install mitsuba): the "
                             "Mitsuba tests are skipped (%s)" % e))
        else:
            probe = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True,
                                   text=True, timeout=300)
            if probe.returncode == 0:
                _variant.append(("ok", "llvm_ad_rgb"))
            else:
                _variant.append(("skip", "Mitsuba's llvm_ad_rgb variant does not run here "
                                 "(Dr.Jit needs libLLVM >= 16, e.g. Debian's libllvm19; exit %d: "
                                 "%s): the Mitsuba tests are skipped (its scalar variants "
                                 "audit one item at a time, too slow for a ci audit)"
                                 % (probe.returncode, probe.stderr.strip()[-200:])))
    status, what = _variant[0]
    if status == "skip":
        pytest.skip(what)
    import mitsuba as mi
    mi.set_variant(what)
    return mi
