#!/usr/bin/env python3
"""Writes a Mitsuba 3 scene of N shapes (default 61 000) just under mfh's 1 MiB scene limit:
nothing in it has a microfacet model, so mfh must read all of it and refuse it.

    gen_mitsuba.py OUT.xml [N]

Ten shapes a line (17 bytes each) keep 61 000 shapes at 1.04 MB.
"""
import sys

out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 61000
lines = ['<scene version="3.0.0">']
for start in range(0, n, 10):
    lines.append('<shape type="a"/>' * min(10, n - start))
lines.append("</scene>")
text = "\n".join(lines) + "\n"
with open(out, "w") as f:
    f.write(text)
print("%d shapes, %d bytes" % (n, len(text.encode())))
