//! The G-code reader: what it refuses (each error naming the 1-based line and its text) and
//! what it reads, with Klipper's `gcode_move` semantics (docs/printing.md, "G-code").

use cdpr_printing::gcode::{
    GcodeError, Instruction, LimitChange, Move, MoveKind, Program, Skipped, read,
};

/// What a refused line must give.
#[derive(Debug, Clone, Copy)]
enum Refusal {
    /// `Malformed` whose reason contains this.
    Malformed(&'static str),
    /// `Unsupported` naming this command.
    Unsupported(&'static str),
    /// `OutOfRange` of this key and value.
    OutOfRange(&'static str, f64),
}

/// Reads `bad` as the third line of a file whose other lines are fine and checks the error.
fn check_refused(bad: &str, expected: Refusal) {
    let file = format!("G28\nG1 X1 Y1 F600\n{bad}\nG1 X2\n");
    let err = read(&file, [0.0; 3]).expect_err(bad);
    let shown = err.to_string();
    assert!(shown.contains("line 3"), "{bad}: `{shown}` names no line 3");
    assert!(
        shown.contains(bad),
        "{bad}: `{shown}` does not quote the line"
    );
    match (&err, expected) {
        (GcodeError::Malformed { line, text, reason }, Refusal::Malformed(part)) => {
            assert_eq!((*line, text.as_str()), (3, bad));
            assert!(
                reason.contains(part),
                "{bad}: reason `{reason}` lacks `{part}`"
            );
            assert!(shown.contains(reason.as_str()));
        }
        (
            GcodeError::Unsupported {
                line,
                text,
                command,
                ..
            },
            Refusal::Unsupported(name),
        ) => {
            assert_eq!((*line, text.as_str(), command.as_str()), (3, bad, name));
            assert!(shown.contains(name));
        }
        (
            GcodeError::OutOfRange {
                line,
                text,
                key,
                value,
                ..
            },
            Refusal::OutOfRange(k, v),
        ) => {
            assert_eq!((*line, text.as_str(), key.as_str(), *value), (3, bad, k, v));
            assert!(shown.contains(k));
        }
        _ => panic!("{bad}: expected {expected:?}, got {err:?}"),
    }
}

#[test]
fn malformed_lines_are_refused_by_line_and_text() {
    use Refusal::Malformed as M;
    for (bad, expected) in [
        ("G1 X1.2.3", M("`1.2.3` is not a number")),
        ("G1 X", M("X without a value")),
        ("G1 X1 X2", M("X given twice")),
        ("G1 X1 x2", M("X given twice")),
        ("G1 X--1", M("is not a number")),
        ("G1 X1 /", M("`/` where a parameter letter")),
        ("G1 X1 Q2", M("parameter Q is not one of X, Y, Z, E, F")),
        ("G0 X1 I2", M("parameter I is not one of X, Y, Z, E, F")),
        ("G4 X1", M("parameter X is not one of P")),
        ("G28 W", M("parameter W is not one of X, Y, Z")),
        ("G92 E", M("E without a value")),
        ("G92 A0", M("parameter A is not one of X, Y, Z, E")),
        (
            "SET_VELOCITY_LIMIT ACCEL=abc",
            M("ACCEL: `abc` is not a number"),
        ),
        ("SET_VELOCITY_LIMIT ACCEL=inf", M("is not a number")),
        ("SET_VELOCITY_LIMIT ACCEL", M("expected KEY=value")),
        // A comment stays part of the quoted text.
        ("G1 X1.2.3 ; perimeter", M("`1.2.3` is not a number")),
    ] {
        check_refused(bad, expected);
    }
}

#[test]
fn unsupported_commands_are_refused_by_name() {
    use Refusal::Unsupported as U;
    for (bad, expected) in [
        ("G4 S2", U("G4 S")),
        ("G4 P100 S2", U("G4 S")),
        ("G2 X1 Y1 I1 J0", U("G2")),
        ("G3 X1 Y1 I1 J0", U("G3")),
        ("g2 x1 y1 i1 j0", U("G2")),
        ("G20", U("G20")),
        ("G10", U("G10")),
        ("G11", U("G11")),
        (
            "SET_VELOCITY_LIMIT ACCEL_TO_DECEL=1000",
            U("SET_VELOCITY_LIMIT ACCEL_TO_DECEL"),
        ),
    ] {
        check_refused(bad, expected);
    }
}

#[test]
fn out_of_range_values_are_refused_with_key_and_value() {
    use Refusal::OutOfRange as R;
    for (bad, expected) in [
        ("G1 F0", R("F", 0.0)),
        ("G1 X5 F-5", R("F", -5.0)),
        ("G4 P-1", R("P", -1.0)),
        ("M204 S0", R("S", 0.0)),
        ("M204 P1000 T-1", R("T", -1.0)),
        ("M220 S0", R("S", 0.0)),
        ("M221 S-10", R("S", -10.0)),
        ("SET_VELOCITY_LIMIT VELOCITY=0", R("VELOCITY", 0.0)),
        ("SET_VELOCITY_LIMIT ACCEL=-3000", R("ACCEL", -3000.0)),
        (
            "SET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY=-1",
            R("SQUARE_CORNER_VELOCITY", -1.0),
        ),
        (
            "SET_VELOCITY_LIMIT MINIMUM_CRUISE_RATIO=1",
            R("MINIMUM_CRUISE_RATIO", 1.0),
        ),
        (
            "SET_VELOCITY_LIMIT MINIMUM_CRUISE_RATIO=-0.1",
            R("MINIMUM_CRUISE_RATIO", -0.1),
        ),
    ] {
        check_refused(bad, expected);
    }
}

/// The first bad line stops the reading: a later bad line is not the one reported.
#[test]
fn the_first_bad_line_is_reported() {
    let err = read("G1 X1\n\nG20\nG1 F0\n", [0.0; 3]).unwrap_err();
    assert!(
        matches!(err, GcodeError::Unsupported { line: 3, .. }),
        "{err:?}"
    );
}

fn moves(program: &Program) -> Vec<Move> {
    program
        .instructions
        .iter()
        .filter_map(|i| match i {
            Instruction::Move(m) => Some(*m),
            _ => None,
        })
        .collect()
}

fn ends(program: &Program) -> Vec<[f64; 4]> {
    moves(program).iter().map(|m| m.end).collect()
}

#[test]
fn g91_makes_xyz_and_e_relative_and_g90_restores_absolute() {
    let program = read(
        "G1 X10 Y10 Z1 E1 F1200\nG91\nG1 X1 Y-2 E0.5\nG1 Z0.25\nG90\nG1 X0 E1\n",
        [0.0; 3],
    )
    .unwrap();
    assert_eq!(
        ends(&program),
        vec![
            [10.0, 10.0, 1.0, 1.0],
            [11.0, 8.0, 1.0, 1.5],
            [11.0, 8.0, 1.25, 1.5],
            [0.0, 8.0, 1.25, 1.0],
        ]
    );
}

#[test]
fn m83_makes_only_e_relative() {
    let program = read(
        "M83\nG1 X10 E1 F600\nG1 X20 E1\nG1 E-0.5\nM82\nG1 X30 E5\n",
        [0.0; 3],
    )
    .unwrap();
    assert_eq!(
        ends(&program),
        vec![
            [10.0, 0.0, 0.0, 1.0],
            [20.0, 0.0, 0.0, 2.0],
            [20.0, 0.0, 0.0, 1.5],
            [30.0, 0.0, 0.0, 5.0],
        ]
    );
}

#[test]
fn g92_shifts_the_given_axes_and_without_arguments_all_four() {
    let program = read(
        "G1 X10 Y10 E2 F600\nG92 X0 E0\nG1 X5 E1\nG92\nG1 X1 Y1 Z1 E1\n",
        [0.0; 3],
    )
    .unwrap();
    assert_eq!(
        ends(&program),
        vec![
            [10.0, 10.0, 0.0, 2.0],
            // X and E read from 10 and 2 now; Y unshifted.
            [15.0, 10.0, 0.0, 3.0],
            // G92 alone: every axis reads 0 where it is.
            [16.0, 11.0, 1.0, 4.0],
        ]
    );
    // G92 produces no instruction of its own.
    assert_eq!(program.instructions.len(), 3);
}

#[test]
fn g28_x_homes_only_x_and_clears_only_its_offset() {
    let home = [1.0, 2.0, 3.0];
    let program = read(
        "G92 X10 Y20\nG28 X\nG1 X5 Y5 F600\nG28\nG1 X5 Y5 Z5\n",
        home,
    )
    .unwrap();
    assert_eq!(program.start, [1.0, 2.0, 3.0, 0.0]);
    // G92 gives no instruction: the first is the homing.
    assert_eq!(
        program.instructions[0],
        Instruction::Home {
            line: 2,
            position: [1.0, 2.0, 3.0],
        }
    );
    let e = ends(&program);
    // X: homed, its G92 offset gone; Y keeps the offset (2 − 20 = −18).
    assert_eq!(e[0], [5.0, -13.0, 3.0, 0.0]);
    // G28 without axes homes and clears all three.
    assert_eq!(e[1], [5.0, 5.0, 5.0, 0.0]);
    // After the first move, G28 alone reports all three at home.
    assert_eq!(
        program.instructions[2],
        Instruction::Home {
            line: 4,
            position: [1.0, 2.0, 3.0],
        }
    );
}

#[test]
fn g28_keeps_the_other_axes_where_they_are() {
    let program = read("G1 X5 Y6 Z7 F600\nG28 Y\n", [0.0; 3]).unwrap();
    assert_eq!(
        program.instructions[1],
        Instruction::Home {
            line: 2,
            position: [5.0, 0.0, 7.0],
        }
    );
}

#[test]
fn speed_is_25_mm_s_until_f_and_f_alone_moves_nothing() {
    let program = read("G1 X1\nG1 F600\nG0 X2\nG1 X2\n", [0.0; 3]).unwrap();
    let m = moves(&program);
    // A line that changes nothing (F only, or the same target) gives no move.
    assert_eq!(m.len(), 2);
    assert_eq!((m[0].line, m[0].speed), (1, 25.0));
    assert_eq!((m[1].line, m[1].speed), (3, 600.0 * (1.0 / 60.0)));
}

#[test]
fn m220_scales_speeds_as_klipper_does() {
    let program = read(
        "G1 X1 F3000\nM220 S50\nG1 X2\nG1 X3 F1200\nM220\nG1 X4\n",
        [0.0; 3],
    )
    .unwrap();
    let speeds: Vec<f64> = moves(&program).iter().map(|m| m.speed).collect();
    // Klipper: speed = F · speed_factor with speed_factor = S / (60 · 100); M220 rescales the
    // current speed: speed / old factor · new factor.
    let half = 50.0 / (60.0 * 100.0);
    let full = 100.0 / (60.0 * 100.0);
    let at_50 = 3000.0 * (1.0 / 60.0) / (1.0 / 60.0) * half;
    let f1200 = 1200.0 * half;
    assert_eq!(
        speeds,
        vec![3000.0 * (1.0 / 60.0), at_50, f1200, f1200 / half * full]
    );
    for (got, want) in speeds.iter().zip([50.0, 25.0, 10.0, 20.0]) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}

#[test]
fn m221_scales_extrusion_and_keeps_the_files_e_position() {
    let program = read(
        "M221 S90\nG1 X1 E10 F600\nM221 S100\nG1 X2 E11\nM83\nM221 S50\nG1 X3 E1\n",
        [0.0; 3],
    )
    .unwrap();
    let e: Vec<f64> = ends(&program).iter().map(|p| p[3]).collect();
    // E10 at 90 % → 9; back at 100 % the file's E10 is where the filament is, so E11 adds 1;
    // relative E1 at 50 % adds 0.5.
    assert_eq!(e.len(), 3);
    assert!((e[0] - 9.0).abs() < 1e-12, "{e:?}");
    assert!((e[1] - 10.0).abs() < 1e-12, "{e:?}");
    assert!((e[2] - 10.5).abs() < 1e-12, "{e:?}");
}

fn accel_changes(program: &Program) -> Vec<(usize, LimitChange)> {
    program
        .instructions
        .iter()
        .filter_map(|i| match i {
            Instruction::Limits { line, change } => Some((*line, *change)),
            _ => None,
        })
        .collect()
}

#[test]
fn m204_reads_s_or_the_smaller_of_p_and_t_and_skips_p_alone() {
    let program = read(
        "M204 S3000\nM204 P2000 T1500\nM204 P2500\nM204 T2500\nM204 S1000 P5 T4\nm204 p800 t900\n",
        [0.0; 3],
    )
    .unwrap();
    let accel = |a: f64| LimitChange {
        max_accel: Some(a),
        ..LimitChange::default()
    };
    assert_eq!(
        accel_changes(&program),
        vec![
            (1, accel(3000.0)),
            (2, accel(1500.0)),
            (5, accel(1000.0)),
            (6, accel(800.0)),
        ]
    );
    assert_eq!(
        program.skipped,
        vec![Skipped {
            command: "M204 (without S, or P and T)".to_string(),
            first_line: 3,
            count: 2,
        }]
    );
}

#[test]
fn set_velocity_limit_reads_its_four_keys() {
    let program = read(
        "SET_VELOCITY_LIMIT VELOCITY=300 ACCEL=5000 SQUARE_CORNER_VELOCITY=8 MINIMUM_CRUISE_RATIO=0.25\n\
         set_velocity_limit accel=700\nSET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY=0 MINIMUM_CRUISE_RATIO=0\n",
        [0.0; 3],
    )
    .unwrap();
    assert_eq!(
        accel_changes(&program),
        vec![
            (
                1,
                LimitChange {
                    max_velocity: Some(300.0),
                    max_accel: Some(5000.0),
                    square_corner_velocity: Some(8.0),
                    minimum_cruise_ratio: Some(0.25),
                }
            ),
            (
                2,
                LimitChange {
                    max_accel: Some(700.0),
                    ..LimitChange::default()
                }
            ),
            (
                3,
                LimitChange {
                    square_corner_velocity: Some(0.0),
                    minimum_cruise_ratio: Some(0.0),
                    ..LimitChange::default()
                }
            ),
        ]
    );
}

#[test]
fn dwells_and_waits() {
    let program = read(
        "G4 P500\nG4\nM400\nM109 S215\nM190 S60\nG4 P0.5\n",
        [0.0; 3],
    )
    .unwrap();
    assert_eq!(
        program.instructions,
        vec![
            Instruction::Dwell {
                line: 1,
                seconds: 0.5
            },
            Instruction::Dwell {
                line: 2,
                seconds: 0.0
            },
            Instruction::WaitForMoves { line: 3 },
            Instruction::WaitForMoves { line: 4 },
            Instruction::WaitForMoves { line: 5 },
            Instruction::Dwell {
                line: 6,
                seconds: 0.0005
            },
        ]
    );
    assert!(program.skipped.is_empty());
}

#[test]
fn skipped_commands_are_listed_once_with_count_and_first_line() {
    let program = read(
        "M104 S200\nM107\nG1 X1\nM104 S210\nM106 S255\nM107\nM117 Printing 50%\nSET_FAN_SPEED FAN=part SPEED=0.5\nM862.3 P \"MK3S\"\n",
        [0.0; 3],
    )
    .unwrap();
    let s = |command: &str, first_line, count| Skipped {
        command: command.to_string(),
        first_line,
        count,
    };
    assert_eq!(
        program.skipped,
        vec![
            s("M104", 1, 2),
            s("M107", 2, 2),
            s("M106", 5, 1),
            s("M117", 7, 1),
            s("SET_FAN_SPEED", 8, 1),
            s("M862.3", 9, 1),
        ]
    );
    assert_eq!(program.instructions.len(), 1);
}

#[test]
fn slicer_types_map_to_move_kinds() {
    let types = [
        ("External perimeter", MoveKind::ExternalPerimeter),
        ("Perimeter", MoveKind::Perimeter),
        ("Overhang perimeter", MoveKind::Perimeter),
        ("Internal infill", MoveKind::Infill),
        ("Solid infill", MoveKind::Infill),
        ("Top solid infill", MoveKind::Infill),
        ("Bridge infill", MoveKind::Infill),
        ("Gap fill", MoveKind::Infill),
        ("Ironing", MoveKind::Infill),
        ("Skirt/Brim", MoveKind::Other),
        ("Support material", MoveKind::Other),
        ("Custom", MoveKind::Other),
        // OrcaSlicer / Bambu names.
        ("Outer wall", MoveKind::ExternalPerimeter),
        ("Inner wall", MoveKind::Perimeter),
        ("Sparse infill", MoveKind::Infill),
    ];
    let mut text = String::from("M83\nG1 X0.5 E0.01 F600\n");
    for (i, (name, _)) in types.iter().enumerate() {
        text += &format!(";TYPE:{name}\nG1 X{} E0.01\n", i + 1);
    }
    let program = read(&text, [0.0; 3]).unwrap();
    let kinds: Vec<MoveKind> = moves(&program).iter().map(|m| m.kind).collect();
    // Before any ;TYPE: an extruding move is Other.
    assert_eq!(kinds[0], MoveKind::Other);
    let expected: Vec<MoveKind> = types.iter().map(|(_, k)| *k).collect();
    assert_eq!(kinds[1..], expected[..]);
}

#[test]
fn moves_that_do_not_extrude_are_travel() {
    let program = read(
        ";TYPE:Perimeter\nG1 X1 E1 F600\nG1 X2\nG1 X3 E0.5\nG1 E1.5\nG1 E1.2\nG1 X4 E1.3\n",
        [0.0; 3],
    )
    .unwrap();
    let kinds: Vec<MoveKind> = moves(&program).iter().map(|m| m.kind).collect();
    assert_eq!(
        kinds,
        vec![
            MoveKind::Perimeter,
            MoveKind::Travel, // no E
            MoveKind::Travel, // retracting while moving
            MoveKind::Travel, // extrude-only (unretract)
            MoveKind::Travel, // extrude-only (retract)
            MoveKind::Perimeter,
        ]
    );
}

#[test]
fn layer_changes_are_counted_and_tag_the_moves() {
    let program = read(
        "G1 X1 F600\n;LAYER_CHANGE\n;Z:0.2\nG1 X2\nG1 X3\n; LAYER_CHANGE\nG1 X4\n;LAYER_CHANGE\n;LAYER_CHANGE\nG1 X5\n;AFTER_LAYER_CHANGE\nG1 X6\n",
        [0.0; 3],
    )
    .unwrap();
    assert_eq!(program.layers, 4);
    let layers: Vec<(usize, usize)> = moves(&program).iter().map(|m| (m.line, m.layer)).collect();
    assert_eq!(
        layers,
        vec![(1, 0), (4, 1), (5, 1), (7, 2), (10, 4), (12, 4)]
    );
}

#[test]
fn line_numbers_checksums_comments_and_case_are_stripped() {
    let program = read(
        "N10 G1 X5 Y6 F600*45\nn11 g1 x7 y8*12 ; comment\nN12 M83*3\nG1X9Y10E1\n  g0 x1 ; travel\n; only a comment\n\nN13*77\ng21\ng90\n",
        [0.0; 3],
    )
    .unwrap();
    assert_eq!(
        ends(&program),
        vec![
            [5.0, 6.0, 0.0, 0.0],
            [7.0, 8.0, 0.0, 0.0],
            [9.0, 10.0, 0.0, 1.0],
            [1.0, 10.0, 0.0, 1.0],
        ]
    );
    let lines: Vec<usize> = moves(&program).iter().map(|m| m.line).collect();
    assert_eq!(lines, vec![1, 2, 4, 5]);
    assert!(program.skipped.is_empty(), "{:?}", program.skipped);
}

#[test]
fn crlf_line_endings_read_like_lf() {
    let lf = read("G1 X1 F600\n;LAYER_CHANGE\nG1 X2 Y3\n", [0.0; 3]).unwrap();
    let crlf = read("G1 X1 F600\r\n;LAYER_CHANGE\r\nG1 X2 Y3\r\n", [0.0; 3]).unwrap();
    assert_eq!(lf, crlf);
    assert_eq!(crlf.layers, 1);
}

/// After `G92 E0` an absolute E target is stored as value + base, as Klipper does, so E
/// differences are those of the stored positions.
#[test]
fn e_positions_are_stored_relative_to_the_base() {
    let program = read(
        "G1 X1 E0.3 F600\nG92 E0\nG1 X2 E0.1\nG1 X3 E0.2\n",
        [0.0; 3],
    )
    .unwrap();
    let e: Vec<f64> = ends(&program).iter().map(|p| p[3]).collect();
    assert_eq!(e, vec![0.3, 0.1 + 0.3, 0.2 + 0.3]);
}

/// Klipper's M220/M221 read S only (100 % without it): Marlin's valueless flags `B` (backup)
/// and `R` (restore) are ignored there, so `M220 B` is not an error and sets 100 %.
#[test]
fn m220_ignores_marlins_backup_and_restore_flags() {
    let program = read(
        "G1 X1 F3000\nM220 S50\nM220 B\nG1 X2\nM220 R S200\nG1 X3\nM221 S90 T0\nG1 X4 E1\n",
        [0.0; 3],
    )
    .unwrap();
    let m = moves(&program);
    assert!((m[1].speed - 50.0).abs() < 1e-12, "{}", m[1].speed);
    assert!((m[2].speed - 100.0).abs() < 1e-12, "{}", m[2].speed);
    assert!((m[3].end[3] - 0.9).abs() < 1e-12, "{:?}", m[3].end);
    check_refused("M220 S", Refusal::Malformed("S without a value"));
}

/// Klipper's M204 reads S first and, when S is given, neither P nor T; without S it reads P
/// and T (each must be > 0 when given) and answers "Invalid M204 command" unless both are.
/// Other letters (Marlin's R) are ignored.
#[test]
fn m204_checks_its_values_in_klippers_order() {
    let program = read("M204 S1000 P0\nM204 S2000 R0\nM204 R\n", [0.0; 3]).unwrap();
    let accels: Vec<(usize, Option<f64>)> = accel_changes(&program)
        .iter()
        .map(|(line, c)| (*line, c.max_accel))
        .collect();
    assert_eq!(accels, vec![(1, Some(1000.0)), (2, Some(2000.0))]);
    assert_eq!(program.skipped.len(), 1);
    assert_eq!(program.skipped[0].first_line, 3);
    check_refused("M204 T0", Refusal::OutOfRange("T", 0.0));
    check_refused("M204 P0 T1000", Refusal::OutOfRange("P", 0.0));
    check_refused("M204 P1000 T0", Refusal::OutOfRange("T", 0.0));
    check_refused("M204 S", Refusal::Malformed("S without a value"));
}
