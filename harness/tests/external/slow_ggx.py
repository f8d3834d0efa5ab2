"""The pure-Python GGX of examples/external/ggx.py answering every request after a pause of
SECONDS (argv[1], default 0.2): a model slow enough for the record budget's test to stop its
checks (harness/tests/record_budget.rs)."""
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "examples", "external"))
import mfh_protocol  # noqa: E402
import ggx  # noqa: E402

PAUSE = float(sys.argv[1]) if len(sys.argv) > 1 else 0.2
_answer = mfh_protocol.answer


def slow_answer(request, *args):
    if request.get("op") != "describe":
        time.sleep(PAUSE)
    return _answer(request, *args)


mfh_protocol.answer = slow_answer
ggx.main("slow_ggx.py")
