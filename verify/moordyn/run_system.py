"""Runs a MoorDyn system of points and lines (its Python wheel, `pip install moordyn`) for the
spatial cross-code tests of `verify/tests/moordyn_spatial.rs`, which write the system as JSON on
stdin and read MoorDyn's answer as JSON on stdout. Nothing MoorDyn computes is stored in the
repository.

The case (MoorDyn's frame: z up; in air: rho = 0, no drag, no added mass, no bending, undamped):
  types:    [{"ea": N, "mu": kg/m}, ...]                      line types, numbered from 0
  points:   [{"fixed": bool, "position": [x, y, z], "mass": kg}, ...]   numbered from 0
  lines:    [{"type": k, "a": point, "b": point, "length": unstrained m, "segments": n}, ...]
  initial:  {"points": [[x, y, z, vx, vy, vz] per point],
             "lines": [[[x, y, z, vx, vy, vz] per interior node] per line]}
            loaded through MoorDyn's state file (its own catenary start is not used)
  gravity:  m/s^2; dt: MoorDyn's RK4 step dtM [s]; t_end, sample [s]; watch: a point's index;
  watch_node (optional): [line, node], a line's node (0 = its end a) to watch as well
The answer: "samples" (times), "watch" (the watched point's [x, y, z] per sample), "dt", and
with watch_node "node" (that node's [x, y, z] per sample).
"""

import json
import os
import struct
import sys
import tempfile

import moordyn

HEAD = """--------------------- MoorDyn Input File ------------------------------------
cdpr-bench cross-code system
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA     BA/-zeta    EI    Cd     Ca     CdAx    CaAx
(name)     (m)      (kg/m)     (N)    (N-s/-)     (-)   (-)    (-)    (-)     (-)
"""
POINTS = """---------------------- POINTS --------------------------------
ID   Attachment  X      Y     Z      M      V        CdA   CA
(#)   (-)        (m)    (m)   (m)    (kg)   (m^3)    (m^2) (-)
"""
LINES = """---------------------- LINES --------------------------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  Outputs
(#)  (name)    (#)      (#)      (m)       (-)      (-)
"""
OPTIONS = """---------------------- OPTIONS -----------------------------------------
{dt!r}   dtM
RK4      tScheme
{g!r}    g
0        rho
1000     WtrDpth
-------------------------- OUTPUTS --------------------------------
--------------------- need this line ------------------
"""


def input_file(case):
    text = HEAD
    for k, t in enumerate(case["types"]):
        text += "t%d  0.0015  %r  %r  0  0  0  0  0  0\n" % (k, float(t["mu"]), float(t["ea"]))
    text += POINTS
    for k, p in enumerate(case["points"]):
        x, y, z = (float(v) for v in p["position"])
        kind = "Fixed" if p["fixed"] else "Free"
        text += "%d  %s  %r  %r  %r  %r  0  0  0\n" % (k + 1, kind, x, y, z, float(p["mass"]))
    text += LINES
    for k, line in enumerate(case["lines"]):
        text += "%d  t%d  %d  %d  %r  %d  -\n" % (
            k + 1,
            line["type"],
            line["a"] + 1,
            line["b"] + 1,
            float(line["length"]),
            int(line["segments"]),
        )
    return text + OPTIONS.format(dt=float(case["dt"]), g=float(case["gravity"]))


def load_initial(system, tmp, initial):
    """Writes every point's and every line's interior nodes' state into the file MoorDyn saves
    (MoorDyn 2.x: b"MoorDyn", u8 major, u8 minor, u64 count, u64 instances, then per instance
    u64 rows, u64 cols and the f64 rows [x, y, z, vx, vy, vz]: points first, then lines) and
    loads it back, so the header stays MoorDyn's own."""
    saved = os.path.join(tmp, "saved.bin")
    moordyn.SaveState(system, saved)
    with open(saved, "rb") as f:
        data = bytearray(f.read())
    assert data[:7] == b"MoorDyn", "not a MoorDyn state file"
    offset = 9
    _, instances = struct.unpack_from("<QQ", data, offset)
    offset += 16
    states = [[p] for p in initial["points"]] + initial["lines"]
    assert instances == len(states), "%d instances, %d states given" % (instances, len(states))
    for rows in states:
        r, c = struct.unpack_from("<QQ", data, offset)
        assert (r, c) == (len(rows), 6), "block of %d x %d, %d rows given" % (r, c, len(rows))
        for k, row in enumerate(rows):
            struct.pack_into("<6d", data, offset + 16 + 48 * k, *(float(v) for v in row))
        offset += 16 + 8 * r * c
    state = os.path.join(tmp, "state.bin")
    with open(state, "wb") as f:
        f.write(data)
    moordyn.LoadState(system, state)


def run(case):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "system.dat")
        with open(path, "w") as f:
            f.write(input_file(case))
        system = moordyn.Create(path)
        moordyn.SetVerbosity(system, moordyn.LEVEL_ERR)
        moordyn.Init_NoIC(system, [], [])
        load_initial(system, tmp, case["initial"])
        watched = moordyn.GetPoint(system, int(case["watch"]) + 1)
        answer = {"samples": [], "watch": [], "dt": float(case["dt"])}
        node = case.get("watch_node")
        if node is not None:
            line = moordyn.GetLine(system, int(node[0]) + 1)
            answer["node"] = []
        t, sample = 0.0, float(case["sample"])
        steps = int(round(float(case["t_end"]) / sample))
        for k in range(1, steps + 1):
            moordyn.Step(system, [], [], t, sample)
            t = k * sample
            answer["samples"].append(t)
            answer["watch"].append(list(moordyn.GetPointPos(watched)))
            if node is not None:
                answer["node"].append(list(moordyn.GetLineNodePos(line, int(node[1]))))
    return answer


if __name__ == "__main__":
    case = json.load(sys.stdin)
    # MoorDyn prints its progress on the process's standard output: keep that descriptor for the
    # answer and send MoorDyn's writes to standard error.
    answer_fd = os.dup(1)
    os.dup2(2, 1)
    result = run(case)
    os.write(answer_fd, json.dumps(result).encode())
    # As run_case.py: leave without the interpreter's teardown (MoorDyn 2.7.2 may abort there).
    os._exit(0)
