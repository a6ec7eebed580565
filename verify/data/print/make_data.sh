#!/bin/sh
# Regenerates the plans in this directory (not run by CI; needs a Klipper
# checkout and, with --reslice, prusa-slicer 2.5.0 from Debian bookworm).
# Usage: sh make_data.sh /path/to/klipper/klippy [--reslice]
set -eu
KLIPPY=${1:?path to Klipper klippy/ directory}
cd "$(dirname "$0")"
if [ "${2:-}" = "--reslice" ]; then
    python3 make_stl.py .
    for m in cube cylinder; do
        env -u DISPLAY prusa-slicer --export-gcode \
            --nozzle-diameter 0.4 --layer-height 0.2 --first-layer-height 0.2 \
            --output $m.gcode $m.stl
    done
    python3 make_features.py features.gcode
fi
plan() {  # name gcode accel stop_at_layer_change [csv-path]
    python3 klipper_plan.py --klippy "$KLIPPY" --gcode "$2" \
        --max-velocity 300 --max-accel "$3" --square-corner-velocity 5 \
        --minimum-cruise-ratio 0.5 --stop-at-layer-change "$4" \
        --out "${5:-plan_$1_a$3.csv}" --summary "plan_$1_a$3.json"
}
for a in 1000 3000 10000; do
    plan cube_layer1 cube.gcode $a 2
    plan cube_full cube.gcode $a 0
    plan cylinder_layers1-3 cylinder.gcode $a 4
    # full cylinder plans are 3.5 MB each: only the summary (with the
    # CSV's sha256) is kept
    plan cylinder_full cylinder.gcode $a 0 /dev/null
    plan features features.gcode $a 0
done
