#!/usr/bin/env python3
"""examples/external/dielectric.py (pure Python, GGX 0.3, eta 1.5) with its eval answering 1e308
wherever it is not 0: the hostile child of the record budgets, in the pure-Python speed of the
tracker's measurement (bsdf_child.py --huge-eval is the numpy one).

    py_dielectric_child.py [--huge-eval] [dielectric.py's options]
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "examples", "external"))
HUGE = "--huge-eval" in sys.argv
sys.argv = [a for a in sys.argv if a != "--huge-eval"]

import dielectric  # noqa: E402  (parses the remaining options)

if HUGE:
    exact = dielectric.bsdf_eval

    def huge_eval(wi, wo):
        return 1e308 if exact(wi, wo) != 0.0 else 0.0

    # main() looks the functions up in the module when it builds the capabilities
    dielectric.bsdf_eval = huge_eval
dielectric.main()
