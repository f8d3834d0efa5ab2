"""The calls of the harness into a model's callables (used by the extension, mfh._mfh): the
inputs arrive as bytes of native float64 and become numpy arrays; the answers are checked for
shape and go back as bytes of float64 (float32 answers are accepted and widened). Nothing here
is public."""
import traceback

import numpy as np


def _array(data, width):
    a = np.frombuffer(data, dtype=np.float64)
    return a if width == 1 else a.reshape(-1, width)


def _shape(n, width):
    return (n,) if width == 1 else (n, width)


def _answer(name, what, value, n, width):
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError("%s returned %s of type %s, not an array of numbers (%s)"
                        % (name, what, type(value).__name__, e)) from None
    want = _shape(n, width)
    if a.shape != want:
        raise ValueError("%s returned %s of shape %s for %d items; expected shape %s"
                         % (name, what, a.shape, n, want))
    return np.ascontiguousarray(a).tobytes()


def values(function, name, n, width, *inputs):
    """function(*arrays) for n items, answering `width` numbers an item; inputs are (bytes,
    width) pairs."""
    arrays = [_array(data, w) for data, w in inputs]
    return _answer(name, "an array", function(*arrays), n, width)


def sample(function, n, wi, u):
    """sample(wi, u) for n items: (wo, pdf, weight) as bytes."""
    answer = function(_array(*wi), _array(*u))
    if not (isinstance(answer, tuple) and len(answer) == 3):
        raise TypeError("sample returned %s; expected a tuple (wo, pdf, weight) of shapes "
                        "(%d, 3), (%d,), (%d,)" % (type(answer).__name__, n, n, n))
    wo, pdf, weight = answer
    return (_answer("sample", "wo", wo, n, 3), _answer("sample", "pdf", pdf, n, 1),
            _answer("sample", "weight", weight, n, 1))


def format_error(exc, tb):
    """An exception with its traceback, as Python prints it."""
    return "".join(traceback.format_exception(type(exc), exc, tb)).rstrip()
