"""Runs one cable case in MoorDyn (its Python wheel, `pip install moordyn`) for the cross-code
tests of `verify/tests/moordyn.rs`, which write the case as JSON on stdin and read MoorDyn's
answer as JSON on stdout. Nothing MoorDyn computes is stored in the repository: every number the
tests compare with comes from this run.

The case, in the plane y = 0 with z up (MoorDyn's frame):
  line:     {"ea": N, "mu": kg/m, "length": unstrained m, "segments": N}
  anchor:   [x, z] of end A (fixed)
  end:      [x, z] of end B; fixed unless "end_mass" (kg) makes it a free point
  gravity:  m/s^2
  initial:  optional [[x, z, vx, vz], ...] of the interior nodes (and then the free end):
            loaded through MoorDyn's state file instead of its own catenary start
  dt:       MoorDyn's time step dtM [s] (RK4), "t_end" and "sample" [s] for the run (t_end 0:
            only the start)
The answer: "start" (node positions at t = 0, both ends included, [[x, z], ...]), "samples"
(times), "nodes" (per sample, the node positions, both ends included), "anchor_tension" [N] per
sample and "dt" MoorDyn used.
"""

import json
import os
import struct
import sys
import tempfile

import moordyn

TEMPLATE = """--------------------- MoorDyn Input File ------------------------------------
cdpr-bench cross-code case
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA     BA/-zeta    EI    Cd     Ca     CdAx    CaAx
(name)     (m)      (kg/m)     (N)    (N-s/-)     (-)   (-)    (-)    (-)     (-)
cable      0.0015   {mu!r}     {ea!r}  0          0     0      0      0       0
---------------------- POINTS --------------------------------
ID   Attachment  X      Y     Z      M      V        CdA   CA
(#)   (-)        (m)    (m)   (m)    (kg)   (m^3)    (m^2) (-)
1     Fixed      {ax!r}  0     {az!r}  0      0        0     0
2     {kind}     {bx!r}  0     {bz!r}  {mass!r}  0    0     0
---------------------- LINES --------------------------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  Outputs
(#)  (name)    (#)      (#)      (m)       (-)      (-)
1    cable      1        2        {length!r}  {segments}   -
---------------------- OPTIONS -----------------------------------------
{dt!r}   dtM
RK4      tScheme
{g!r}    g
0        rho
100      WtrDpth
-------------------------- OUTPUTS --------------------------------
--------------------- need this line ------------------
"""


def load_initial(system, tmp, interior, free_end):
    """Sets the interior nodes (and a free end) through MoorDyn 2.x's state file: b"MoorDyn",
    u8 major, u8 minor, u64 count, u64 instances, then per instance u64 rows, u64 cols and the
    f64 data, points first, then the line's interior nodes, each row [x, y, z, vx, vy, vz]. The
    file MoorDyn saves is patched in place, so its header stays MoorDyn's own."""
    saved = os.path.join(tmp, "saved.bin")
    moordyn.SaveState(system, saved)
    with open(saved, "rb") as f:
        data = bytearray(f.read())
    assert data[:7] == b"MoorDyn", "not a MoorDyn state file"
    offset = 9
    _, instances = struct.unpack_from("<QQ", data, offset)
    offset += 16
    blocks = []
    for _ in range(instances):
        r, c = struct.unpack_from("<QQ", data, offset)
        blocks.append((offset + 16, r, c))
        offset += 16 + 8 * r * c
    assert len(blocks) == 3, "expected two points and one line"

    def patch(block, states):
        at, r, c = block
        assert (r, c) == (len(states), 6), "state block of %d x %d" % (r, c)
        for k, (x, z, vx, vz) in enumerate(states):
            struct.pack_into("<6d", data, at + 48 * k, x, 0.0, z, vx, 0.0, vz)

    if free_end is not None:
        patch(blocks[1], [free_end])
    patch(blocks[2], interior)
    state = os.path.join(tmp, "state.bin")
    with open(state, "wb") as f:
        f.write(data)
    moordyn.LoadState(system, state)


def positions(system, line, free_point, segments):
    nodes = [moordyn.GetLineNodePos(line, i) for i in range(segments + 1)]
    if free_point is not None:
        nodes[-1] = moordyn.GetPointPos(free_point)
    return [[p[0], p[2]] for p in nodes]


def run(case):
    line_case = case["line"]
    free = case.get("end_mass") is not None
    text = TEMPLATE.format(
        mu=float(line_case["mu"]),
        ea=float(line_case["ea"]),
        ax=float(case["anchor"][0]),
        az=float(case["anchor"][1]),
        bx=float(case["end"][0]),
        bz=float(case["end"][1]),
        kind="Free" if free else "Fixed",
        mass=float(case.get("end_mass") or 0.0),
        length=float(line_case["length"]),
        segments=int(line_case["segments"]),
        dt=float(case["dt"]),
        g=float(case["gravity"]),
    )
    segments = int(line_case["segments"])
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "case.dat")
        with open(path, "w") as f:
            f.write(text)
        system = moordyn.Create(path)
        moordyn.SetVerbosity(system, moordyn.LEVEL_ERR)
        moordyn.Init_NoIC(system, [], [])
        line = moordyn.GetLine(system, 1)
        free_point = moordyn.GetPoint(system, 2) if free else None
        if case.get("initial") is not None:
            initial = case["initial"]
            interior, end_state = (initial[:-1], initial[-1]) if free else (initial, None)
            assert len(interior) == segments - 1, "initial: one row per interior node"
            load_initial(system, tmp, interior, end_state)
        answer = {
            "start": positions(system, line, free_point, segments),
            "samples": [],
            "nodes": [],
            "anchor_tension": [],
        }
        t, t_end, sample = 0.0, float(case["t_end"]), float(case["sample"])
        steps = int(round(t_end / sample))
        for k in range(1, steps + 1):
            moordyn.Step(system, [], [], t, sample)
            t = k * sample
            answer["samples"].append(t)
            answer["nodes"].append(positions(system, line, free_point, segments))
            tension = moordyn.GetLineNodeTen(line, 0)
            answer["anchor_tension"].append(sum(c * c for c in tension) ** 0.5)
        answer["dt"] = float(case["dt"])
    return answer


if __name__ == "__main__":
    case = json.load(sys.stdin)
    # MoorDyn prints its progress on the process's standard output: keep that descriptor for the
    # answer and send MoorDyn's writes to standard error.
    answer_fd = os.dup(1)
    os.dup2(2, 1)
    result = run(case)
    os.write(answer_fd, json.dumps(result).encode())
    # The wrapper may abort while the interpreter tears down after long runs (MoorDyn 2.7.2):
    # the answer is written, so leave without the teardown.
    os._exit(0)
