#!/usr/bin/env python3
"""Cross-checks reference/golden/lambda_dd.json (generated in Rust by mfh-harness
oracle::precise, double-double tanh-sinh quadrature) against mpmath at 150 digits, by routes
that share nothing with it: Beckmann Lambda = (e^{-a^2}/(a sqrt(pi)) - erfc a)/2, Student
Lambda = A - T with T by the regularized incomplete beta function (as in student.py), D by its
closed forms. Fails if a value differs from mpmath by more than the relative bound stored with
it (or 1e-29); prints the largest differences.

Usage: python3 reference/golden/tools/check_lambda_dd.py
Requires: mpmath (pip install mpmath).
"""
import json
import os
import mpmath as mp

mp.mp.dps = 150
HALF = mp.mpf(1) / 2


def shape(m):
    """(C, s) of a Student member: GGX is C = 2, s = alpha; STD C = gamma, s = alpha sqrt(C-1)."""
    a = mp.mpf(m["alpha"])
    if m["family"] == "ggx":
        return mp.mpf(2), a
    c = mp.mpf(m["gamma"])
    return c, a * mp.sqrt(c - 1)


def lam(m, mu):
    if m["family"] == "beckmann":
        x = mu / mp.mpf(m["alpha"])
        return (mp.exp(-x * x) / (x * mp.sqrt(mp.pi)) - mp.erfc(x)) / 2
    c, s = shape(m)
    x = mu / s
    n = mp.gamma(c - HALF) / (mp.sqrt(mp.pi) * mp.gamma(c - 1))
    w = 1 / (1 + x * x)
    a = n * w ** (c - 3 * HALF) / ((2 * c - 3) * x)
    t = mp.betainc(c - 1, HALF, 0, w, regularized=True) / 2
    return a - t


def d(m, v):
    cos2 = v[2] ** 2 / (v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    tan2 = (v[0] ** 2 + v[1] ** 2) / v[2] ** 2
    if m["family"] == "beckmann":
        a = mp.mpf(m["alpha"])
        return mp.exp(-tan2 / a ** 2) / (mp.pi * a * a * cos2 ** 2)
    c, s = shape(m)
    return (c - 1) / (mp.pi * s * s * cos2 ** 2) * (1 + tan2 / s ** 2) ** (-c)


def main():
    path = os.path.join(os.path.dirname(__file__), "..", "lambda_dd.json")
    golden = json.load(open(path))
    for quantity in ("lambda", "d"):
        worst = mp.mpf(0)
        for row in golden[quantity]:
            v = [mp.mpf(x) for x in row["direction"]]
            m = row["model"]
            exact = lam(m, v[2] / mp.sqrt(v[0] ** 2 + v[1] ** 2)) if quantity == "lambda" else d(m, v)
            diff = abs(mp.mpf(row["decimal"]) - exact) / abs(exact)
            bound = max(mp.mpf(row["relative_bound"]), mp.mpf("1e-29"))
            assert diff <= bound, (quantity, m, row["theta"], mp.nstr(diff, 3), row["relative_bound"])
            worst = max(worst, diff)
        print(quantity, len(golden[quantity]), "values, max relative difference", mp.nstr(worst, 3))


main()
