"""The report of an audit (:class:`Report`) and :func:`per_item`, which turns functions of one
item into the batch functions the audit calls."""
import json
import threading

import numpy as np

# One lock for every function made by per_item: functions of one item are pure Python (the GIL
# runs one at a time anyway), and scripts written for a child process (one caller) keep state
# between calls, e.g. a cache shared by eval and sample, that threads must not interleave.
_PER_ITEM_LOCK = threading.Lock()


class Report:
    """The result of :func:`mfh.audit_bsdf` or :func:`mfh.audit_ndf`: the records the ``mfh``
    CLI writes to report.json, and the CI gate.

    - ``passed``: no record failed or errored (expected failures pass).
    - ``records``: every record as a dict (check, model, case, verdict, value, oracle,
      measured, tolerance, source, ...), in plan order.
    - ``failures``: the failing records (verdict fail, error or unexpected_pass).
    - ``failed_checks``: their check ids, sorted and unique.
    - ``assert_pass()``: raises ``AssertionError`` with the failure table and the line that
      reproduces the run.
    - ``write(out_dir)``: report.json, junit.xml, the artefacts and report.html.
    """

    def __init__(self, inner):
        self._inner = inner
        self._records = None

    @property
    def passed(self):
        return self._inner.passed()

    @property
    def records(self):
        if self._records is None:
            self._records = json.loads(self._inner.records_json())
        return self._records

    @property
    def failures(self):
        return [r for r in self.records if _failed(r)]

    @property
    def failed_checks(self):
        return sorted({r["check"] for r in self.failures})

    @property
    def summary(self):
        return json.loads(self._inner.summary_json())

    @property
    def name(self):
        return self._inner.name

    @property
    def profile(self):
        return self._inner.profile

    @property
    def seed(self):
        return self._inner.seed

    @property
    def command(self):
        """The line that reproduces the run."""
        return self._inner.command

    @property
    def wall_seconds(self):
        return self._inner.wall_seconds

    @property
    def calls(self):
        """(calls of the Python functions, items they answered)."""
        return self._inner.calls

    def failure_table(self):
        return self._inner.failure_table()

    def summary_text(self):
        """The CLI's terminal summary."""
        return self._inner.terminal()

    def assert_pass(self):
        """The CI gate: raises AssertionError with the failure table unless the audit passed."""
        if not self.passed:
            raise AssertionError(self._inner.failure_table())

    def write(self, out_dir):
        """Writes report.json, junit.xml, the records' artefacts (chi-square tables, heat maps)
        and report.html into out_dir (created), as ``mfh audit --out`` does; the paths
        written."""
        import os
        return self._inner.write(os.fspath(out_dir))

    def __bool__(self):
        return self.passed

    def __repr__(self):
        counts = self.summary.get("counts", {})
        text = ", ".join("%s %d" % (k, v) for k, v in sorted(counts.items()) if v)
        head = "<mfh.Report %r: %s, %d records (%s), profile %s, seed %d, %.1f s>" % (
            self.name, "passed" if self.passed else "FAILED", len(self.records), text,
            self.profile, self.seed, self.wall_seconds)
        failed = self.failed_checks
        if failed:
            head += "\nfailed checks: " + ", ".join(failed)
        return head


def _failed(record):
    verdict = record.get("verdict")
    kind = verdict.get("verdict") if isinstance(verdict, dict) else verdict
    return kind in ("fail", "error", "unexpected_pass")


def per_item(function, kind="values"):
    """A batch function from a function of one item (slow: one Python call an item; for
    prototypes and for the examples of the external protocol, whose functions take tuples).
    The items reach ``function`` as tuples of floats; the functions made by ``per_item`` run one
    at a time (one lock), since such functions often share state between calls.

    - ``kind="values"``: ``function(a, b, ...)`` of one row each returns a number;
      the batch function returns an (N,) array.
    - ``kind="direction"``: returns a direction (3 numbers); the batch returns (N, 3).
    - ``kind="sample"``: returns ``(wo, pdf, weight)``; the batch returns the three arrays.
    """
    if kind not in ("values", "direction", "sample"):
        raise ValueError('kind = %r is not one of "values", "direction", "sample"' % (kind,))

    def batch(*arrays):
        rows = zip(*(np.asarray(a).tolist() for a in arrays))
        with _PER_ITEM_LOCK:
            answers = [function(*(tuple(r) for r in row)) for row in rows]
        if kind == "values":
            return np.array(answers, dtype=np.float64)
        if kind == "direction":
            return np.array(answers, dtype=np.float64).reshape(-1, 3)
        wo = np.array([a[0] for a in answers], dtype=np.float64).reshape(-1, 3)
        pdf = np.array([a[1] for a in answers], dtype=np.float64)
        weight = np.array([a[2] for a in answers], dtype=np.float64)
        return wo, pdf, weight

    batch.__name__ = getattr(function, "__name__", "per_item")
    batch.__qualname__ = getattr(function, "__qualname__", batch.__name__)
    batch.__module__ = getattr(function, "__module__", None)
    return batch
