"""The API's contract: arguments refused with the field named, a model's errors as a failing
python.call record, the report's sinks, Ctrl-C. Each audit here runs one cheap check."""
import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from numpy_dielectric import Dielectric

import mfh

MODEL = Dielectric()
CHEAP = ["bsdf.reciprocity"]


def audit(**kw):
    args = dict(eval=MODEL.eval, pdf=MODEL.pdf, sample=MODEL.sample, eta=1.5, checks=CHEAP,
                quiet=True)
    args.update(kw)
    return mfh.audit_bsdf(**args)


@pytest.mark.parametrize("kw, field", [
    (dict(eta=1.0), "eta"), (dict(eta=20.0), "eta"), (dict(profile="fast"), "profile"),
    (dict(transport="photons"), "transport"), (dict(precision="f16"), "precision"),
    (dict(seed=-1), "seed"), (dict(checks=["bsdf.nonsense"]), "checks"),
    (dict(against={"bsdf": "dielectric", "eta": 1.00001}), None),
    (dict(eval=3), "eval"), (dict(ndf={"d": MODEL.d, "g": 1}), "ndf"),
])
def test_bad_arguments_are_refused_naming_the_field(kw, field):
    if field is None:  # an invalid spec is a failing audit.configuration record
        report = audit(**kw)
        assert "audit.configuration" in report.failed_checks, report
        return
    with pytest.raises((ValueError, TypeError)) as e:
        audit(**kw)
    assert field in str(e.value)


def test_a_bad_mfh_seed_is_refused(monkeypatch):
    monkeypatch.setenv("MFH_SEED", "0x2a")
    with pytest.raises(ValueError, match="MFH_SEED"):
        audit()
    monkeypatch.setenv("MFH_SEED", "42")
    assert audit().seed == 42


def test_an_exception_is_a_failing_record_with_its_traceback():
    def eval_(wi, wo):
        raise ZeroDivisionError("my bug")

    report = audit(eval=eval_)
    assert not report.passed and "python.call" in report.failed_checks
    message = [r for r in report.failures if r["check"] == "python.call"][0]["message"]
    assert "ZeroDivisionError: my bug" in message and "eval_" in message, message
    with pytest.raises(AssertionError) as e:
        report.assert_pass()
    assert "python.call" in str(e.value) and "reproduce: MFH_SEED=" in str(e.value)


@pytest.mark.parametrize("bad, words", [
    (lambda wi, wo: MODEL.eval(wi, wo)[:-1], "shape"),
    (lambda wi, wo: MODEL.eval(wi, wo).reshape(-1, 1), "shape"),
    (lambda wi, wo: np.where(wo[:, 2] < 0, np.nan, MODEL.eval(wi, wo)), "NaN"),
    (lambda wi, wo: "values", "not an array"),
])
def test_wrong_answers_are_named(bad, words):
    report = audit(eval=bad)
    failure = [r for r in report.failures if r["check"] == "python.call"]
    assert failure, report
    assert words in failure[0]["message"], failure[0]


def test_the_report_writes_what_the_cli_writes(tmp_path):
    report = audit(checks=["bsdf.chi2"])
    assert report.passed and sum(r["check"] == "bsdf.chi2" for r in report.records) == 5
    written = report.write(tmp_path / "out")
    names = {os.path.basename(p) for p in written}
    assert {"report.json", "junit.xml", "report.html"} <= names, names
    data = json.loads((tmp_path / "out" / "report.json").read_text())
    assert [r["check"] for r in data["records"]] == [r["check"] for r in report.records]
    assert "numpy_dielectric" in repr(report) and "passed" in repr(report)
    assert report.command.startswith("MFH_SEED=%d " % report.seed)


def test_ctrl_c_stops_the_audit_and_raises_keyboard_interrupt():
    """SIGINT during an audit: the calls stop, the checks not started are not run, and
    KeyboardInterrupt reaches the caller (the timeout only guards against a hang)."""
    script = textwrap.dedent("""
        import os, signal, sys, threading, time
        sys.path.insert(0, %r)
        import mfh
        from numpy_dielectric import Dielectric
        # Python's own Ctrl-C handler, as in a terminal: a process started in the background
        # by a non-interactive shell inherits SIGINT ignored, and Python then keeps ignoring it.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        m = Dielectric()
        calls = []
        def slow_eval(wi, wo):
            calls.append(len(wi))
            time.sleep(0.01)
            return m.eval(wi, wo)
        threading.Timer(2.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        t = time.monotonic()
        try:
            mfh.audit_bsdf(eval=slow_eval, pdf=m.pdf, sample=m.sample, eta=1.5, quiet=True)
        except KeyboardInterrupt:
            print("interrupted after %%.1f s, %%d eval calls" %% (time.monotonic() - t,
                                                              len(calls)))
            sys.exit(130)
        print("not interrupted")
    """ % os.path.dirname(os.path.abspath(__file__)))
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=900)
    print(run.stdout)
    assert run.returncode == 130, (run.stdout, run.stderr)
    assert "interrupted; stopping the running checks" in run.stderr, run.stderr


def test_per_item_batches_a_function_of_one_item():
    f = mfh.per_item(lambda wi, wo: wi[2] + wo[2])
    assert f(np.array([[0, 0, 1.0]]), np.array([[0, 0, 0.5]])).tolist() == [1.5]
    s = mfh.per_item(lambda wi, u: ((0.0, 0.0, 1.0), 2.0, 0.5), "sample")
    wo, pdf, weight = s(np.zeros((2, 3)), np.zeros((2, 3)))
    assert wo.shape == (2, 3) and pdf.tolist() == [2.0, 2.0] and weight.tolist() == [0.5, 0.5]
