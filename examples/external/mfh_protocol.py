"""mfh's external protocol, versions 1 and 2, for the examples beside this file: a model gives
its functions, `serve` does the rest (describe and version negotiation, decoding the request
arrays, encoding the answers, one answer line per request line, shutdown). No dependencies;
numpy only when `serve(..., numpy=True)`.

Protocol (docs/external-protocol.md in the repository): one JSON object per line each
way. mfh's `describe` request offers `"versions":[1,2]`; the answer's `"protocol"` chooses.
- Version 1: arrays are JSON arrays, `[[x,y,z],...]` or `[[u1,u2],...]`.
- Version 2: arrays are base64 (standard, padded) of little-endian float64, row-major, in the
  same JSON line; requests also carry `"n"`, the item count. Decoding is one library call
  (`np.frombuffer(base64.b64decode(s), '<f8')`, or `array('d', base64.b64decode(s))`), which
  is what makes version 2 fast: no float <-> text conversion.
stdout is the protocol channel: log to stderr only.

Options every example takes: --alpha A or --alpha-x AX --alpha-y AY (default 0.3), and
--protocol 1|2 (default 2: the newest that mfh offers), to measure or debug version 1.
"""
import base64
import json
import sys
from array import array
from itertools import chain

VERSIONS = (1, 2)

# The request arrays of each op, in the order the model's function takes them, with the
# numbers per item; sampling ops answer directions ("m"), the others values.
INPUTS = {
    "d": (("m", 3),),
    "lambda": (("w", 3),),
    "g1": (("w", 3), ("m", 3)),
    "g2": (("wo", 3), ("wi", 3), ("m", 3)),
    "sample_wm": (("u", 2),),
    "pdf_wm": (("m", 3),),
    "sample_wm_visible": (("wi", 3), ("u", 2)),
    "pdf_wm_visible": (("wi", 3), ("m", 3)),
    "bsdf_eval": (("wi", 3), ("wo", 3)),
    "bsdf_pdf": (("wi", 3), ("wo", 3)),
    "bsdf_sample": (("wi", 3), ("u", 3)),
}
SAMPLING = ("sample_wm", "sample_wm_visible")
# A BSDF sample answers three arrays: the direction, its density and its weight eval/pdf (a
# failed sample: pdf 0, weight 0, any finite wo). The model's function returns the triple.
BSDF_SAMPLE = (("wo", 3), ("pdf", 1), ("weight", 1))
BIG_ENDIAN = sys.byteorder == "big"


def options(argv=None):
    """(alpha_x, alpha_y, protocol) from the command line."""
    args = sys.argv[1:] if argv is None else argv
    opts = dict(zip(args[::2], args[1::2]))
    ax = float(opts.get("--alpha-x", opts.get("--alpha", 0.3)))
    ay = float(opts.get("--alpha-y", opts.get("--alpha", ax)))
    protocol = int(opts.get("--protocol", VERSIONS[-1]))
    if protocol not in VERSIONS:
        sys.exit("--protocol must be one of %s" % (VERSIONS,))
    return ax, ay, protocol


def outputs(op):
    """The answer arrays of op: (name, numbers per item)."""
    if op in SAMPLING:
        return (("m", 3),)
    if op == "bsdf_sample":
        return BSDF_SAMPLE
    return (("values", 1),)


def _part(job):
    """A worker's share of a version-2 batch (module level, so that a pool can call it): the
    raw little-endian f64 bytes of each request array in, those of each answer array out (bytes
    travel between processes far cheaper than lists of tuples)."""
    function, op, raws, extra = job
    columns = []
    for raw, width in raws:
        a = array("d", raw)
        if BIG_ENDIAN:
            a.byteswap()
        columns.append(list(zip(*(a[k::width] for k in range(width)))) if width > 1 else a)
    result = [function(*row, *extra) for row in zip(*columns)]
    names = outputs(op)
    if len(names) > 1:
        result = PurePython.columns(result, len(names))
    else:
        result = [result]
    out = []
    for column, (_, width) in zip(result, names):
        a = array("d", chain.from_iterable(column) if width > 1 else column)
        if BIG_ENDIAN:
            a.byteswap()
        out.append(a.tobytes())
    return out


class PurePython:
    """Arrays as lists of tuples; the model's functions take one item at a time. With
    workers > 1, batches of at least MIN_SPLIT items are split among that many forked
    processes (pure Python is one core per process)."""

    MIN_SPLIT = 2048

    def __init__(self, workers=1):
        self.pool = None
        if workers > 1:
            import multiprocessing

            self.pool = multiprocessing.get_context("fork").Pool(workers)
            self.workers = workers

    @staticmethod
    def decode(field, width):
        if not isinstance(field, str):
            return field
        a = array("d", base64.b64decode(field))
        if BIG_ENDIAN:
            a.byteswap()
        return list(zip(*(a[k::width] for k in range(width))))

    @staticmethod
    def call(function, arrays, extra):
        return [function(*row, *extra) for row in zip(*arrays)]

    def split(self, op, function, request, extra):
        """The answer of a large version-2 request computed by the workers, or None (no pool,
        a small batch, or JSON arrays)."""
        fields = [(request[name], width) for name, width in INPUTS[op]]
        if self.pool is None or not all(isinstance(f, str) for f, _ in fields):
            return None
        raws = [(base64.b64decode(f), width) for f, width in fields]
        n = len(raws[0][0]) // (8 * raws[0][1])
        if n < self.MIN_SPLIT or any(len(r) != 8 * w * n for r, w in raws):
            return None
        step = -(-n // self.workers)
        jobs = [(function, op, [(r[8 * w * k:8 * w * (k + step)], w) for r, w in raws], extra)
                for k in range(0, n, step)]
        parts = self.pool.map(_part, jobs)
        return {name: base64.b64encode(b"".join(p[j] for p in parts))
                for j, (name, _) in enumerate(outputs(op))}

    @staticmethod
    def columns(result, k):
        """The k columns of a list of k-tuples."""
        return [list(c) for c in zip(*result)] if result else [[] for _ in range(k)]

    @staticmethod
    def encode(result, width, version):
        if version == 1:
            return result
        a = array("d", chain.from_iterable(result) if width > 1 else result)
        if BIG_ENDIAN:
            a.byteswap()
        return base64.b64encode(a.tobytes())


class Numpy:
    """Arrays as numpy arrays of shape (n, width); the model's functions take whole batches."""

    def __init__(self):
        import numpy

        self.np = numpy

    def decode(self, field, width):
        if isinstance(field, str):
            return self.np.frombuffer(base64.b64decode(field), "<f8").reshape(-1, width)
        return self.np.array(field, dtype=float).reshape(-1, width)

    @staticmethod
    def call(function, arrays, extra):
        return function(*arrays, *extra)

    @staticmethod
    def columns(result, k):
        """A numpy function answers a tuple of k arrays already."""
        return result

    def encode(self, result, width, version):
        if version == 1:
            return result.tolist()
        data = self.np.ascontiguousarray(result, dtype="<f8")
        return base64.b64encode(data.tobytes())


def answer(request, describe, functions, codec, version):
    """The answer object for one request (without its id)."""
    op = request["op"]
    if op == "describe":
        return dict(describe, protocol=version, capabilities=list(functions))
    if op not in functions:
        return {"error": "unknown op " + repr(op)}
    extra = [request["masking"]] if op == "g2" else []
    if version == 2 and isinstance(codec, PurePython):
        shared = codec.split(op, functions[op], request, extra)
        if shared is not None:
            return shared
    arrays = [codec.decode(request[name], width) for name, width in INPUTS[op]]
    result = codec.call(functions[op], arrays, extra)
    if op in SAMPLING:
        return {"m": codec.encode(result, 3, version)}
    if op == "bsdf_sample":
        columns = codec.columns(result, len(BSDF_SAMPLE))
        return {name: codec.encode(column, width, version)
                for (name, width), column in zip(BSDF_SAMPLE, columns)}
    return {"values": codec.encode(result, 1, version)}


def encode_line(reply):
    """The answer line. Version 2's arrays (base64 bytes) are spliced in as they are: base64
    needs no JSON escaping, and json.dumps would scan (and copy) megabytes to find that out."""
    arrays = {k: v for k, v in reply.items() if isinstance(v, bytes)}
    head = json.dumps({k: v for k, v in reply.items() if k not in arrays}).encode("ascii")
    parts = [head[:-1]]
    for name, data in arrays.items():
        parts += [b', "', name.encode("ascii"), b'": "', data, b'"']
    parts.append(b"}\n")
    return b"".join(parts)


def serve(name, parameters, functions, protocol=VERSIONS[-1], numpy=False, extra=None,
          workers=1):
    """Answers mfh's requests on stdin until `shutdown` or end of input.

    functions: op name -> function (its capabilities, in the order given). Pure Python: called
    per item with tuples; numpy=True: called per batch with (n, 3) or (n, 2) arrays, returning
    an (n,) or (n, 3) array (bsdf_sample: a (wo, pdf, weight) triple per item, or of arrays).
    protocol: the newest version to speak. extra: more fields of the describe answer (a BSDF's
    "eta" and "transport"). workers: processes sharing large pure-Python batches."""
    codec = Numpy() if numpy else PurePython(workers)
    describe = dict(extra or {}, name=name, parameters=parameters)
    version = 1
    out = sys.stdout.buffer
    for line in sys.stdin.buffer:
        request = json.loads(line)
        op = request.get("op")
        if op == "shutdown":
            return
        if op == "describe":
            offered = request.get("versions", [1])
            version = max(v for v in offered + [1] if v in VERSIONS and v <= protocol)
        try:
            reply = answer(request, describe, functions, codec, version)
        except Exception as e:  # the model's own failure: an error answer, not a crash
            reply = {"error": "%s: %s" % (type(e).__name__, e)}
        reply["id"] = request.get("id")
        out.write(encode_line(reply))
        out.flush()
