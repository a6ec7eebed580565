#!/usr/bin/env python3
"""Run Klipper's own toolhead planner offline on a G-code file.

This script contains no Klipper code.  It imports Klipper's python modules
(klippy/) from a directory given with --klippy, builds the real objects
    gcode.GCodeDispatch            (G-code line parsing / dispatch)
    extras/gcode_move.GCodeMove    (G0/G1, G90/G91, M82/M83, G92, M220/M221)
    toolhead.ToolHead + ToolHeadCommandHelper
                                   (Move, LookAheadQueue, G4, M204, M400,
                                    SET_VELOCITY_LIMIT)
    kinematics/extruder.PrinterExtruder
                                   (extruder check_move / calc_junction)
    kinematics/none                (no per-axis kinematic limits)
    extras/heaters.PrinterHeaters.set_temperature (M104/M109 path only)
around a fake `printer` whose hardware parts (mcu, motion_queuing/trapq,
chelper, steppers, heater sensors, reactor) are stubs, feeds the G-code
through Klipper's dispatcher and records every segment that the toolhead
hands to its trapezoid motion queue (trapq_append).

Output CSV: one row per kinematic (XYZ-moving) segment, SI units:
    t_start,accel_t,cruise_t,decel_t,start_x,start_y,start_z,
    dir_x,dir_y,dir_z,start_v,cruise_v,end_v,accel
t_start is Klipper's own `next_move_time` (print time in s) passed to
trapq_append.  Extrude-only moves are planned by Klipper (they occupy
print time, so later t_start values include them) but produce no row.
G4 dwells advance print time as in Klipper.  Values are mm-based Klipper
numbers divided by 1000 (positions, velocities, accel); times untouched.

Deliberate deviations from a live printer (all are "wall-clock" effects,
not planner effects):
  * the fake mcu reports an estimated print time far in the past, so the
    toolhead never inserts re-priming gaps (BUFFER_TIME_START etc.) and
    print time only advances by move durations and dwells; the first
    move starts at print time 0;
  * reactor timers never fire: no "priming timer" flush and no runout flush
    from motion_queuing's background step generation.  Lookahead flushes
    therefore happen exactly where Klipper's code flushes synchronously:
    lazy flushes when LookAheadQueue.add_move reports the junction_flush
    budget is used up, and full flushes on G4, M400, M109 (temperature
    wait), G28 and end of file;
  * G28 takes zero time: it flushes the lookahead (toolhead.set_position)
    and sets the homed axes (those named, or X, Y and Z if none) to 0,
    then applies gcode_move's own home_rails_end handler;
  * M109 does one temperature-wait iteration (one get_last_move_time,
    i.e. a full lookahead flush) and adds no time;
  * unknown commands (M107, M84, M106 without a fan, ...) are ignored
    exactly like Klipper does (it only answers "Unknown command").
"""
import argparse
import collections
import configparser
import hashlib
import importlib
import json
import math
import os
import sys
import types

CSV_HEADER = ("t_start,accel_t,cruise_t,decel_t,start_x,start_y,start_z,"
              "dir_x,dir_y,dir_z,start_v,cruise_v,end_v,accel")


# ----------------------------------------------------------------------
# Stubs for hardware / runtime parts
# ----------------------------------------------------------------------
class _NullCtx:
    def __enter__(self):
        return self

    def __exit__(self, *a):
        return False


class FakeReactor:
    NOW = 0.
    NEVER = 9999999999999999.

    def monotonic(self):
        return 0.

    def register_timer(self, callback, waketime=None):
        return ("timer", callback)

    def update_timer(self, timer, waketime):
        pass

    def unregister_timer(self, timer):
        pass

    def pause(self, waketime):
        return waketime

    def mutex(self, is_locked=False):
        return _NullCtx()

    def assert_no_pause(self):
        return _NullCtx()


class FakeMCU:
    def is_fileoutput(self):
        # No pausing on a full buffer (ToolHead.can_pause = False).
        return True

    def estimated_print_time(self, eventtime):
        # Far in the past: the toolhead never needs to add a restart gap.
        return -1e9


class FakeMotionQueuing:
    """Replaces extras/motion_queuing: hands out trapq handles and a
    recording trapq_append."""

    def __init__(self, recorder):
        self.recorder = recorder
        self.trapqs = []

    def register_flush_callback(self, callback, can_add_trapq=False):
        pass  # background step flushing is not simulated

    def allocate_trapq(self):
        tq = object()
        self.trapqs.append(tq)
        return tq

    def lookup_trapq_append(self):
        return self.recorder.trapq_append

    def calc_step_gen_restart(self, est_print_time):
        return -1e9

    def get_kin_flush_delay(self):
        return 0.001

    def note_mcu_movequeue_activity(self, mq_time, is_step_gen=True):
        pass

    def flush_all_steps(self):
        pass

    def wipe_trapq(self, trapq):
        pass

    def check_step_generation_scan_windows(self):
        pass


class FakeHeater:
    can_extrude = True

    def __init__(self):
        self.target = 0.
        self._busy_polls = 0

    def set_temp(self, temp):
        self.target = temp
        self._busy_polls = 1  # a wait will poll exactly once

    def check_busy(self, eventtime):
        if self._busy_polls:
            self._busy_polls -= 1
            return True
        return False

    def get_status(self, eventtime):
        return {"temperature": self.target, "target": self.target}


def make_fake_heaters(heaters_mod):
    cls = heaters_mod.PrinterHeaters

    class FakeHeaters:
        # Klipper's own M104/M109 path (lookahead callback, wait loop)
        set_temperature = cls.set_temperature
        _wait_for_temperature = cls._wait_for_temperature

        def __init__(self, printer):
            self.printer = printer

        def setup_heater(self, config, gcode_id=None):
            return FakeHeater()

        def _get_temp(self, eventtime):
            return "T:0"
    return FakeHeaters


class FakeHomingState:
    def __init__(self, axes):
        self.axes = axes

    def get_axes(self):
        return self.axes


class Printer:
    """Just enough of klippy.Printer."""

    def __init__(self, gcode_mod, configfile_mod):
        self.reactor = FakeReactor()
        self.objects = collections.OrderedDict()
        self.event_handlers = {}
        self.command_error = gcode_mod.CommandError
        self.config_error = configfile_mod.error
        self.lazy = {}

    def get_reactor(self):
        return self.reactor

    def get_start_args(self):
        return {}

    def add_object(self, name, obj):
        self.objects[name] = obj

    def lookup_object(self, name, default=KeyError):
        if name in self.objects:
            return self.objects[name]
        if default is KeyError:
            raise self.config_error("Unknown config object '%s'" % (name,))
        return default

    def lookup_objects(self, module=None):
        return [(n, o) for n, o in self.objects.items()
                if module is None or n == module or n.startswith(module + " ")]

    def load_object(self, config, section, default=KeyError):
        if section in self.objects:
            return self.objects[section]
        if section in self.lazy:
            obj = self.lazy[section]()
            self.objects[section] = obj
            return obj
        raise self.config_error("Module '%s' not available offline"
                                % (section,))

    def register_event_handler(self, event, callback):
        self.event_handlers.setdefault(event, []).append(callback)

    def send_event(self, event, *params):
        return [cb(*params) for cb in self.event_handlers.get(event, [])]

    def set_rollover_info(self, name, info, log=True):
        pass

    def is_shutdown(self):
        return False

    def invoke_shutdown(self, msg, details={}):
        raise RuntimeError("Klipper shutdown: %s" % (msg,))

    def request_exit(self, result):
        pass

    def get_state_message(self):
        return ("Ready", "ready")


class Recorder:
    """Collects what the toolhead hands to the trapq."""

    def __init__(self):
        self.toolhead_trapq = None
        self.pending = collections.deque()   # moves returned by flush()
        self.rows = []
        self.n_extrude_only = 0
        self.extrude_only_time = 0.
        self.n_flushes = 0
        self.n_lazy_flushes = 0
        self.flush_sizes = []

    def wrap_flush(self, lookahead):
        orig = lookahead.flush

        def flush(lazy=False):
            res = orig(lazy=lazy)
            if res:
                self.n_flushes += 1
                self.n_lazy_flushes += bool(lazy)
                self.flush_sizes.append(len(res))
            for m in res:
                if m.is_kinematic_move:
                    self.pending.append(m)
                else:
                    self.n_extrude_only += 1
                    self.extrude_only_time += m.accel_t + m.cruise_t + m.decel_t
            return res
        lookahead.flush = flush

    def trapq_append(self, tq, print_time, accel_t, cruise_t, decel_t,
                     sx, sy, sz, ax, ay, az, start_v, cruise_v, accel):
        if tq is not self.toolhead_trapq:
            return  # extruder trapq: not part of the output
        m = self.pending.popleft()
        # Consistency: this really is the move flush() returned
        assert (m.accel_t, m.cruise_t, m.decel_t, m.start_v, m.cruise_v,
                m.accel) == (accel_t, cruise_t, decel_t, start_v, cruise_v,
                             accel)
        assert tuple(m.start_pos[:3]) == (sx, sy, sz)
        self.rows.append((print_time, accel_t, cruise_t, decel_t,
                          sx, sy, sz, ax, ay, az,
                          start_v, cruise_v, m.end_v, accel))


# ----------------------------------------------------------------------
def install_module_stubs():
    """chelper (C helpers), mcu and stepper are never needed offline."""
    class FfiLib:
        def trapq_set_position(self, *a):
            pass

        def trapq_append(self, *a):
            raise AssertionError("unexpected direct trapq_append")

    ffi_lib = FfiLib()
    chelper = types.ModuleType("chelper")
    chelper.get_ffi = lambda: (None, ffi_lib)
    sys.modules["chelper"] = chelper
    sys.modules["mcu"] = types.ModuleType("mcu")
    sys.modules["stepper"] = types.ModuleType("stepper")


def build_config_text(a):
    lines = ["[printer]", "kinematics: none",
             "max_velocity: %r" % a.max_velocity,
             "max_accel: %r" % a.max_accel,
             "square_corner_velocity: %r" % a.square_corner_velocity,
             "minimum_cruise_ratio: %r" % a.minimum_cruise_ratio,
             "", "[extruder]",
             "nozzle_diameter: %r" % a.nozzle_diameter,
             "filament_diameter: %r" % a.filament_diameter]
    for opt in ("instantaneous_corner_velocity", "max_extrude_only_velocity",
                "max_extrude_only_accel", "max_extrude_only_distance",
                "max_extrude_cross_section"):
        v = getattr(a, opt)
        if v is not None:
            lines.append("%s: %r" % (opt, v))
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--klippy", required=True,
                    help="path of Klipper's klippy/ directory")
    ap.add_argument("--gcode", required=True)
    ap.add_argument("--out", required=True, help="CSV output path")
    ap.add_argument("--summary", help="JSON summary output path")
    ap.add_argument("--max-velocity", type=float, default=300.)
    ap.add_argument("--max-accel", type=float, default=3000.)
    ap.add_argument("--square-corner-velocity", type=float, default=5.)
    ap.add_argument("--minimum-cruise-ratio", type=float, default=0.5)
    ap.add_argument("--nozzle-diameter", type=float, default=0.4)
    ap.add_argument("--filament-diameter", type=float, default=1.75)
    ap.add_argument("--instantaneous-corner-velocity", type=float)
    ap.add_argument("--max-extrude-only-velocity", type=float)
    ap.add_argument("--max-extrude-only-accel", type=float)
    ap.add_argument("--max-extrude-only-distance", type=float)
    ap.add_argument("--max-extrude-cross-section", type=float)
    ap.add_argument("--stop-at-layer-change", type=int, default=0,
                    help="stop reading before the N-th ';LAYER_CHANGE' "
                         "comment line (N=2: first layer only); 0 = whole file")
    ap.add_argument("--ignore-m204", action="store_true",
                    help="drop M204 lines (keep the configured max_accel)")
    ap.add_argument("--no-lazy-flush", action="store_true",
                    help="DIAGNOSTIC ONLY (not Klipper behaviour): never "
                         "flush lazily, plan each flush-free stretch in "
                         "one full flush")
    a = ap.parse_args()

    klippy = os.path.abspath(a.klippy)
    sys.path.insert(0, klippy)
    install_module_stubs()
    gcode_mod = importlib.import_module("gcode")
    configfile_mod = importlib.import_module("configfile")
    toolhead_mod = importlib.import_module("toolhead")
    extruder_mod = importlib.import_module("kinematics.extruder")
    gcode_move_mod = importlib.import_module("extras.gcode_move")
    heaters_mod = importlib.import_module("extras.heaters")

    if a.no_lazy_flush:
        orig_add = toolhead_mod.LookAheadQueue.add_move

        def add_move(self, move):
            orig_add(self, move)
            return False
        toolhead_mod.LookAheadQueue.add_move = add_move

    printer = Printer(gcode_mod, configfile_mod)
    rec = Recorder()
    printer.add_object("mcu", FakeMCU())
    printer.lazy["motion_queuing"] = lambda: FakeMotionQueuing(rec)
    FakeHeaters = make_fake_heaters(heaters_mod)
    printer.lazy["heaters"] = lambda: FakeHeaters(printer)

    cfg_text = build_config_text(a)
    fileconfig = configparser.RawConfigParser(strict=False,
                                              inline_comment_prefixes=(";", "#"))
    fileconfig.read_string(cfg_text)
    access = {}
    cfg = configfile_mod.ConfigWrapper(printer, fileconfig, access, "printer")

    gcode = gcode_mod.GCodeDispatch(printer)
    printer.add_object("gcode", gcode)
    toolhead = toolhead_mod.ToolHead(cfg)
    printer.add_object("toolhead", toolhead)
    toolhead_mod.ToolHeadCommandHelper(cfg)
    extruder_mod.add_printer_objects(cfg)
    gcode_move = gcode_move_mod.load_config(cfg.getsection("gcode_move"))
    printer.add_object("gcode_move", gcode_move)
    rec.toolhead_trapq = toolhead.get_trapq()
    rec.wrap_flush(toolhead.lookahead)
    extruder = printer.lookup_object("extruder")

    # G28: zero-time "homing" (see module docstring)
    def cmd_G28(gcmd):
        axes = [pos for pos, axis in enumerate("XYZ")
                if gcmd.get(axis, None) is not None] or [0, 1, 2]
        pos = toolhead.get_position()
        for i in axes:
            pos[i] = 0.
        toolhead.set_position(pos, homing_axes=axes)
        gcode_move._handle_home_rails_end(FakeHomingState(axes), None)
    gcode.register_command("G28", cmd_G28)

    responses = []
    gcode.register_output_handler(responses.append)
    printer.send_event("klippy:connect")
    printer.send_event("klippy:ready")

    stats = collections.Counter()
    m204 = []
    layer_changes = 0
    n_lines = 0
    with open(a.gcode, "r") as f:
        for line in f:
            s = line.strip()
            if s.startswith(";LAYER_CHANGE"):
                layer_changes += 1
                if a.stop_at_layer_change and \
                        layer_changes >= a.stop_at_layer_change:
                    break
            n_lines += 1
            code = s.split(";", 1)[0].strip()
            if not code:
                continue
            word = code.split()[0].upper()
            stats[word] += 1
            if word in ("G2", "G3"):
                raise SystemExit("G2/G3 arcs are not supported: %r" % (s,))
            if word == "M204":
                m204.append(code)
                if a.ignore_m204:
                    continue
            before = len(responses)
            gcode._process_commands([line], need_ack=False)
            for r in responses[before:]:
                if r.startswith("!!"):
                    raise SystemExit("Klipper error on %r: %s" % (s, r))
    # End of input: full flush, as Klipper does when the input runs out
    toolhead.flush_step_generation()
    total = toolhead.print_time
    assert not rec.pending

    out_lines = [CSV_HEADER]
    for r in rec.rows:
        (t, at, ct, dt, sx, sy, sz, ax, ay, az, sv, cv, ev, acc) = r
        vals = (t, at, ct, dt, sx / 1000., sy / 1000., sz / 1000.,
                ax, ay, az, sv / 1000., cv / 1000., ev / 1000.,
                acc / 1000.)
        out_lines.append(",".join(repr(float(v)) for v in vals))
    csv_text = "\n".join(out_lines) + "\n"
    with open(a.out, "w") as f:
        f.write(csv_text)

    unknown = sorted(set(r for r in responses if "Unknown command" in r))
    summary = {
        "gcode": os.path.basename(a.gcode),
        "lines_read": n_lines,
        "stop_at_layer_change": a.stop_at_layer_change,
        "rows": len(rec.rows),
        "csv_sha256": hashlib.sha256(csv_text.encode()).hexdigest(),
        "total_print_time_s": total,
        "total_print_time_repr": repr(total),
        "extrude_only_moves": rec.n_extrude_only,
        "extrude_only_time_s": rec.extrude_only_time,
        "lookahead_flushes": rec.n_flushes,
        "lazy_flushes": rec.n_lazy_flushes,
        "no_lazy_flush_diagnostic": a.no_lazy_flush,
        "m204_lines": m204,
        "m204_ignored": a.ignore_m204,
        "final_max_accel": toolhead.max_accel,
        "extruder": {
            "max_extrude_ratio": extruder.max_extrude_ratio,
            "max_e_velocity": extruder.max_e_velocity,
            "max_e_accel": extruder.max_e_accel,
            "instant_corner_v": extruder.instant_corner_v,
        },
        "command_counts": dict(sorted(stats.items())),
        "unknown_command_responses": unknown,
        "config": cfg_text,
    }
    if a.summary:
        with open(a.summary, "w") as f:
            json.dump(summary, f, indent=1)
            f.write("\n")
    sys.stderr.write("rows=%d total_print_time=%r\n" % (len(rec.rows), total))


if __name__ == "__main__":
    main()
