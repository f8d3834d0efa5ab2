#!/usr/bin/env python3
"""Generates reference/golden/student.json: high-precision values of the standardized Student
Smith Lambda, of 2F1(1/2, C-1/2; 3/2; -x^2) and of Gamma(z+1/2)/Gamma(z), with mpmath at 60
significant digits (independent of every closed form in mfh-reference: Lambda is the difference A - T of
its two defining integrals, T by mpmath's incomplete beta function or Euler's integral for
2F1, at 80 digits beyond those the difference cancels; cross-checked against mpmath.quad of
Lambda = (1/x) * integral_x^inf (q - x) P2(q) dq where C >= 1.6 and Lambda > 1e-100: the run
fails if they differ by more than 1e-9, and records the largest difference.).

Usage: python3 reference/golden/tools/student.py > reference/golden/student.json
Requires: mpmath (pip install mpmath).
"""
import json
import mpmath as mp

mp.mp.dps = 60

CS = ["1.500000001", "1.500001", "1.6", "2", "2.5", "3", "3.5", "4", "5", "7.5", "12", "20",
      "100", "10000", "1000000", "100000000"]
# a = x * sqrt(C - 1): the Beckmann-like standardized cotangent
AS = ["1e-8", "1e-4", "0.01", "0.1", "0.5", "0.8", "1", "1.2", "1.5", "2", "3", "5", "10", "30",
      "100", "1e4", "1e8"]


def norm(c):
    return mp.gamma(c - mp.mpf(1) / 2) / (mp.sqrt(mp.pi) * mp.gamma(c - 1))


def lam_beta(c, x, dps=150):
    """A - T with T the upper tail, by the incomplete beta function (w < 1/2) or by
    1/2 - N x 2F1(1/2, C-1/2; 3/2; -x^2) (w >= 1/2), at enough digits to absorb the
    cancellation: 150, or 80 more than the digits A - T cancels."""
    with mp.workdps(dps):
        c = mp.mpf(c)
        x = mp.mpf(x)
        w = 1 / (1 + x * x)
        n = norm(c)
        a = n * w ** (c - mp.mpf(3) / 2) / ((2 * c - 3) * x)
        if w < mp.mpf(1) / 2:
            t = mp.betainc(c - 1, mp.mpf(1) / 2, 0, w, regularized=True) / 2
        else:
            t = mp.mpf(1) / 2 - n * x * f21(c, x)
        v = a - t
        lost = int(mp.log10(abs(a) / abs(v))) if v != 0 else dps
        if lost > dps - 80:
            return lam_beta(c, x, lost + 100)
        return +v


def f21(c, x):
    """2F1(1/2, C-1/2; 3/2; -x^2) = (1/x) int_0^x (1+q^2)^(1/2-C) dq (Euler's integral)."""
    with mp.workdps(mp.mp.dps + 90):
        c = mp.mpf(c)
        x = mp.mpf(x)
        scale = 1 / mp.sqrt(c)
        pts = [mp.mpf(0)] + [k * scale for k in (1, 4, 16, 64, 256) if k * scale < x] + [x]
        return mp.quad(lambda q: (1 + q * q) ** (mp.mpf(1) / 2 - c), pts) / x


def lam_integral(c, x):
    """Lambda from its definition, (1/x) int_x^inf (q - x) P2(q) dq, with q = x/u for x >= 1
    (the algebraic tail becomes a polynomial-like integrand on (0, 1]) and break points every
    decay length (1 + x^2)/((2C - 1) x + sqrt(C)) for x < 1. A cross-check only."""
    with mp.workdps(80):
        c = mp.mpf(c)
        x = mp.mpf(x)
        n = norm(c)
        p2 = lambda q: n * mp.exp((mp.mpf(1) / 2 - c) * mp.log1p(q * q))
        if x >= 1:
            g = lambda u: (x / u - x) * p2(x / u) * x / (u * u) if u > 0 else mp.mpf(0)
            return mp.quad(g, mp.linspace(0, 1, 9)) / x
        h = (1 + x * x) / ((2 * c - 1) * x + mp.sqrt(c))
        pts = [x] + [x + k * h for k in (1, 4, 16, 64, 256, 1024, 4096)] + [mp.inf]
        return mp.quad(lambda q: (q - x) * p2(q), pts) / x


def main():
    lam = []
    worst = [mp.mpf(0)]
    hyp = []
    for cs in CS:
        c = mp.mpf(float(cs))  # the f64 nearest the decimal: the value the Rust tests pass
        for as_ in AS:
            xf = mp.mpf(float(mp.mpf(as_) / mp.sqrt(c - 1)))
            v = lam_beta(c, xf)
            if c >= mp.mpf("1.6") and abs(v) > mp.mpf("1e-100"):
                # heavy tails (C < 1.6, q^(2-2C)) converge too slowly for mp.quad
                q = lam_integral(c, xf)
                d = abs(q - v) / abs(v)
                assert d <= mp.mpf("1e-9"), (cs, as_, v, q)
                worst[0] = max(worst[0], d)
            if mp.mpf("1e-300") < abs(v) < mp.mpf("1e300"):
                lam.append({"c": float(c), "x": float(xf), "lambda": mp.nstr(v, 20)})
            z = -xf ** 2
            h = f21(c, xf)
            if mp.mpf("1e-300") < abs(h):
                hyp.append({"c": float(c), "z": float(z), "value": mp.nstr(h, 20)})
    ratio = []
    for zs in ["1e-9", "1e-6", "0.1", "0.5", "0.6", "1", "1.5", "2", "3.5", "10", "29.5", "30", "31", "99",
               "1000", "1e4", "1e6", "1e8"]:
        z = mp.mpf(zs)
        ratio.append({"z": float(z), "value": mp.nstr(mp.gamma(z + mp.mpf(1) / 2) / mp.gamma(z), 20)})
    out = {
        "provenance": {
            "tool": "mpmath " + mp.__version__,
            "precision": "60 significant digits (mp.dps = 60); values rounded to 20",
            "command": "python3 reference/golden/tools/student.py > reference/golden/student.json",
            "integral_vs_beta_max_rel_diff": mp.nstr(worst[0], 3),
            "definitions": {
                "lambda": "standardized Student Smith Lambda_C(x) = (1/x) int_x^inf (q-x) N (1+q^2)^(1/2-C) dq,"
                          " N = Gamma(C-1/2)/(sqrt(pi) Gamma(C-1)); x is the f64 given (exactly)",
                "hyp2f1": "2F1(1/2, C-1/2; 3/2; z) = (1/x) int_0^x (1+q^2)^(1/2-C) dq, x = sqrt(-z), z the f64 given (exactly)",
                "gamma_half_ratio": "Gamma(z+1/2)/Gamma(z)",
            },
        },
        "lambda": lam,
        "hyp2f1": hyp,
        "gamma_half_ratio": ratio,
    }
    print(json.dumps(out, indent=1))


main()
