#!/usr/bin/env python3
"""Reference table for plain Reeds-Shepp lengths, produced by an independent implementation.

Uses the `rsplan` package (pip install rsplan numpy), which implements the 48 Reeds-Shepp words
after Reeds & Shepp (1990). All its candidate paths are computed and the shortest total length
is kept (rsplan's own `path()` may prefer a slightly longer path with fewer segments, so it is
not used). Turning radius 1 m: poses are drawn in metres and lengths are in metres.

Each candidate's end point is checked by sampling its waypoints; pairs where the reference's
shortest path does not reach the goal within 1 mm are dropped (and counted).

Output: rs_table.json = {"turn_radius_m": 1.0, "pairs": [[x0,y0,th0,x1,y1,th1,length], ...]}
Run: python3 tools/maneuvers/reference/make_rs_table.py
"""
import json
import math
import os
import random

from rsplan import planner

R = 1.0
N = 1200
rng = random.Random(20261130)
pairs = []
dropped = 0
for i in range(N):
    scale = rng.choice([0.5, 2.0, 6.0])  # near, medium and far goals, in units of R
    start = (rng.uniform(-scale, scale), rng.uniform(-scale, scale), rng.uniform(-math.pi, math.pi))
    goal = (rng.uniform(-scale, scale), rng.uniform(-scale, scale), rng.uniform(-math.pi, math.pi))
    paths = planner._solve_path(start, goal, R, 0.001)
    best = min(paths, key=lambda p: p.total_length)
    end = best.waypoints()[-1]
    dth = math.atan2(math.sin(end.yaw - goal[2]), math.cos(end.yaw - goal[2]))
    if math.hypot(end.x - goal[0], end.y - goal[1]) > 1e-3 or abs(dth) > 1e-3:
        dropped += 1
        continue
    pairs.append([*start, *goal, best.total_length])

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "rs_table.json")
with open(out, "w") as f:
    json.dump({"turn_radius_m": R, "generator": "rsplan 1.0.10, shortest of all candidates",
               "dropped_not_reaching_goal": dropped, "pairs": pairs}, f, indent=0)
print(f"{len(pairs)} pairs written to {out}, {dropped} dropped")
