#!/usr/bin/env python3
"""Fits the polynomials behind `special::student_tail::beckmann_lambda` for a >= 1.5 and
prints them as Rust source (the `BECKMANN_PIECES` table), after checking the f64 evaluation
against mpmath.

The function fitted is

    F(a) = 4 sqrt(pi) a^3 e^{a^2} Lambda(a) = 2 a^2 - 2 sqrt(pi) a^3 erfcx(a)
         = 1 - 3t/2 + 15t^2/4 - ...            (a -> infinity)

(Lambda(a) = (e^{-a^2}/(a sqrt(pi)) - erfc a)/2, seed 001 Table 1, gamma -> infinity), which
lies in [0.65, 1) for a >= 1.5: Lambda = e^{-a^2} F / (4 sqrt(pi) a^3) then has no cancellation.
On each piece [a0, a1) = [0.5, 1), [1, 1.5), ..., [3.5, 4) the polynomial is the Chebyshev
interpolant of F in s = (a - mid)/half; on [4, infinity) in s = (t - mid)/half over
t = 1/a^2 in (0, 1/16]. Each is truncated where the sum of the dropped
coefficients is < 1e-18, converted to monomials in s (Horner in f64).

Usage: python3 reference/golden/tools/beckmann_lambda_fit.py
Requires: mpmath (pip install mpmath).
"""
import math
import sys

import mpmath as mp

mp.mp.dps = 60
PIECES = [(0.5 + 0.5 * k, 1.0 + 0.5 * k) for k in range(7)] + [(4.0, math.inf)]
NODES = 48
DROP = mp.mpf("1e-18")


def f_exact(a):
    a = mp.mpf(a)
    return 2 * a * a - 2 * mp.sqrt(mp.pi) * a ** 3 * mp.erfc(a) * mp.exp(a * a)


def f_of_t(t):
    if t == 0:
        return mp.mpf(1)
    return f_exact(1 / mp.sqrt(t))


def chebyshev(f, t0, t1):
    mid, half = (t0 + t1) / 2, (t1 - t0) / 2
    xs = [mp.cos(mp.pi * (k + mp.mpf(1) / 2) / NODES) for k in range(NODES)]
    fs = [f(mid + half * x) for x in xs]
    c = [sum(fs[k] * mp.cos(mp.pi * j * (k + mp.mpf(1) / 2) / NODES) for k in range(NODES))
         * 2 / NODES for j in range(NODES)]
    c[0] /= 2
    n = next(n for n in range(NODES) if sum(abs(x) for x in c[n + 1:]) < DROP)
    return c[: n + 1]


def to_monomial(c):
    """Chebyshev coefficients -> monomial coefficients (T_{k+1} = 2 s T_k - T_{k-1})."""
    n = len(c)
    t_prev, t_cur = [mp.mpf(1)] + [mp.mpf(0)] * (n - 1), [mp.mpf(0), mp.mpf(1)] + [mp.mpf(0)] * (n - 2)
    p = [mp.mpf(0)] * n
    for k in range(n):
        tk = t_prev if k == 0 else t_cur
        if k >= 2:
            t_next = [2 * (t_cur[i - 1] if i > 0 else 0) - t_prev[i] for i in range(n)]
            t_prev, t_cur = t_cur, t_next
            tk = t_cur
        for i in range(n):
            p[i] += c[k] * tk[i]
    return p


def horner(p, s):
    acc = 0.0
    for x in reversed(p):
        acc = acc * s + x
    return acc


def main():
    out = []
    worst = 0.0
    for a0, a1 in PIECES:
        if a1 == math.inf:
            t0, t1, f = mp.mpf(0), 1 / mp.mpf(a0) ** 2, f_of_t
        else:
            t0, t1, f = mp.mpf(a0), mp.mpf(a1), f_exact
        c = chebyshev(f, t0, t1)
        p = [float(x) for x in to_monomial(c)]
        mid, inv_half = float((t0 + t1) / 2), float(2 / (t1 - t0))
        # Check the f64 evaluation against mpmath at 2000 points of the piece.
        hi = a1 if a1 != math.inf else 40.0
        for i in range(2001):
            a = a0 + (hi - a0) * i / 2000
            x = 1.0 / (a * a) if a1 == math.inf else a
            got = horner(p, (x - mid) * inv_half)
            want = f_exact(a)
            e = float(abs(got - want) / want)
            worst = max(worst, e)
        out.append((a0, a1, mid, inv_half, p))
        print(f"piece [{a0}, {a1}): degree {len(p) - 1}", file=sys.stderr)
    print(f"max relative error of F in f64: {worst:.2e}", file=sys.stderr)
    for a0, a1, mid, inv_half, p in out:
        print(f"    // a in [{a0}, {a1}): degree {len(p) - 1}")
        print(f"    Piece {{\n        mid: {mid!r},\n"
              f"        inv_half: {inv_half!r},\n        coefficients: &[")
        for x in p:
            print(f"            {x!r},")
        print("        ],\n    },")


if __name__ == "__main__":
    main()
