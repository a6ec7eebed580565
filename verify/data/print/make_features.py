#!/usr/bin/env python3
"""Write features.gcode: a small synthetic file that exercises planner
paths the sliced parts do not (extruder instantaneous_corner_velocity
junctions, extrude-only and retract-with-XY limits, Z+E moves, M204 S /
P+T / invalid P-only, SET_VELOCITY_LIMIT, G4, G91/M83, G92, M220/M221,
sub-1e-9 and zero-length moves, speeds above max_velocity).
Deterministic: fixed seed; the file kept next to this script is canonical."""
import math
import random
import sys

r = random.Random(20240601)
L = ["; synthetic planner feature test", "G28", "G90", "M82", "G92 E0",
     "G1 Z0.3 F600", "G1 X10 Y10 F30000 ; above max_velocity (300 mm/s)"]
e = 0.0
x, y = 10.0, 10.0
# 1. zigzag with changing extrusion ratio -> extruder ICV junction limits
for i in range(60):
    nx = x + r.uniform(2.0, 6.0)
    ny = y + (3.0 if i % 2 else -3.0) * r.uniform(0.5, 1.5)
    d = math.hypot(nx - x, ny - y)
    e += d * r.choice([0.02, 0.035, 0.05, 0.08])
    L.append("G1 X%.3f Y%.3f E%.5f F%d" % (nx, ny, e, r.choice([1800, 3600, 9000])))
    x, y = nx, ny
# 1b. collinear segments with alternating extrusion ratio: only the
#     extruder's instantaneous_corner_velocity limits these junctions
for i in range(12):
    nx = x + 2.5
    e += 2.5 * (0.1 if i % 2 else 0.02)
    L.append("G1 X%.3f Y%.3f E%.5f F6000" % (nx, y, e))
    x = nx
# 2. retraction / unretraction (extrude-only) and retract while moving (wipe)
L += ["G1 E%.5f F2400" % (e - 2.0), "G1 E%.5f F6000" % e,
      "G1 X%.3f Y%.3f E%.5f F3000 ; wipe" % (x - 3, y + 1, e - 0.8)]
e -= 0.8
L += ["G92 E0", "G1 E0.8 F1800"]
e = 0.8
# 3. Z+E move (no XY: limited like extrude-only), Z-only moves
L += ["G1 Z0.5 E1.0 F600", "G1 Z0.7 F7800", "G1 Z0.5"]
e = 1.0
# 4. M204 variants and a square path
L += ["M204 S1000"]
for (px, py) in [(x, y + 20), (x + 20, y + 20), (x + 20, y), (x, y)]:
    e += 20 * 0.04
    L.append("G1 X%.3f Y%.3f E%.5f F6000" % (px, py, e))
L += ["M204 P5000 T2000"]
for (px, py) in [(x + 10, y + 10), (x, y + 20), (x - 10, y + 10), (x, y)]:
    e += 14.142 * 0.04
    L.append("G1 X%.3f Y%.3f E%.5f F12000" % (px, py, e))
L += ["M204 P800 ; invalid in Klipper (needs P and T): ignored",
      "G1 X%.3f Y%.3f F12000" % (x + 30, y)]
# 5. dwell, relative modes, tiny and zero-length moves
L += ["G4 P250", "G91", "M83",
      "G1 X5 Y0.5 E0.2 F4800", "G1 X5 Y-0.5 E0.2", "G1 X0.0000000001 E0.05",
      "G1 X0 Y0", "G1 X-2 Y3 E0.1", "G4 P0", "G90", "M82", "G92 E0"]
x, y = x + 30 + 8, y + 3
# 6. SET_VELOCITY_LIMIT changes mid-path, M220/M221 factors
L += ["SET_VELOCITY_LIMIT VELOCITY=80 SQUARE_CORNER_VELOCITY=2 MINIMUM_CRUISE_RATIO=0.2",
      "M220 S150", "M221 S90"]
e = 0.0
for k in range(24):  # 24-gon
    a = 2 * math.pi * k / 24
    e += 2.6 * 0.04
    L.append("G1 X%.3f Y%.3f E%.5f F6000" % (x + 10 * math.cos(a), y + 10 * math.sin(a), e))
L += ["SET_VELOCITY_LIMIT ACCEL=7000 VELOCITY=300 SQUARE_CORNER_VELOCITY=5 MINIMUM_CRUISE_RATIO=0.5",
      "M220 S100", "M221 S100"]
for k in range(24):
    a = -2 * math.pi * k / 24
    e += 2.6 * 0.04
    L.append("G1 X%.3f Y%.3f E%.5f F9000" % (x + 10 * math.cos(a), y + 10 * math.sin(a), e))
L += ["G1 E%.5f F3000" % (e - 1.5), "G1 X0 Y0 F18000", "G4 P100"]
out = sys.argv[1] if len(sys.argv) > 1 else "features.gcode"
open(out, "w").write("\n".join(L) + "\n")
