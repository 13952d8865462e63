#!/usr/bin/env python3
"""High-precision Fresnel integrals C(x) = ∫0^x cos(πt²/2) dt, S(x) = ∫0^x sin(πt²/2) dt.

mpmath (pip install mpmath) at 40 significant digits; the values are written with 17 digits.
Output: fresnel_table.json = [[x, C, S], ...]. Run: python3 tools/maneuvers/reference/make_fresnel_table.py
"""
import json
import os
import random

import mpmath

mpmath.mp.dps = 40
xs = [0.0, 1e-8, 1e-4, 0.01, 0.1, 0.25, 0.5, 0.75, 1.0, 1.2, 1.49, 1.5, 1.51, 2.0, 2.5, 3.0,
      4.0, 5.0, 7.5, 10.0, 20.0, 50.0, 100.0, 1000.0]
rng = random.Random(4)
xs += [rng.uniform(0.0, 6.0) for _ in range(200)]
xs += [-x for x in xs[1:12]]
rows = [[x, float(mpmath.fresnelc(x)), float(mpmath.fresnels(x))] for x in xs]
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fresnel_table.json")
with open(out, "w") as f:
    json.dump(rows, f, indent=0)
print(f"{len(rows)} rows written to {out}")
