//! Bundle reader tests: one per refusal of the spec page, acceptance of
//! reordered tables and columns with unit conversion, hostile input, and a
//! proptest-driven fuzz over mutated bundles.

use super::*;
use proptest::prelude::*;
use std::path::Path;

const TOML: &str = r#"
format = "ceiling-measured/1"
name = "t1"

[structure]
length_x_m = 2.4
length_y_m = 3.6
module_m = 0.6
main_tee_spacing_m = 1.2
hanger_spacing_m = 1.2
hanger_length_m = 1.0
panel_mass_kg = 1.2
boundary = "semi-free"
nominal_gap_mm = 19.0

[[sensors]]
id = "A1"
kind = "acceleration"
x_m = 1.2
y_m = 1.8
direction = "x"
units = "g"

[[sensors]]
id = "D1"
kind = "displacement"
x_m = 0.0
y_m = 1.8
direction = "x"
units = "m"

[[runs]]
id = "r1"
file = "runs/r1.csv"
input_x = "base_ax"
input_units = "m/s2"
role = "calibration"
"#;

const RUN: &str = "# a comment\nt,base_ax,A1,D1\n0.0,0.1,0.5,0.001\n0.01,0.2,,0.002\n0.02,0.3,nan,0.003\n0.03,0.4,1.0,\n";

/// A bundle folder with `toml` as bundle.toml and `run` as runs/r1.csv.
pub(super) fn make(toml: &str, run: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("runs")).unwrap();
    std::fs::write(dir.path().join("bundle.toml"), toml).unwrap();
    std::fs::write(dir.path().join("runs/r1.csv"), run).unwrap();
    dir
}

fn refused(toml: &str, run: &str) -> String {
    let dir = make(toml, run);
    read_bundle(dir.path()).expect_err("bundle should be refused").to_string()
}

#[test]
fn valid_bundle_is_read_with_units_converted() {
    let dir = make(TOML, RUN);
    let b = read_bundle(dir.path()).unwrap();
    let r = &b.runs[0];
    assert_eq!(r.n_samples(), 4);
    assert!((r.dt_s - 0.01).abs() < 1e-15);
    let a1 = r.sensor("A1").unwrap();
    assert!((a1[0] - 0.5 * 9.80665).abs() < 1e-12 && a1[1].is_nan() && a1[2].is_nan());
    let d1 = r.sensor("D1").unwrap();
    assert!((d1[2] - 3.0).abs() < 1e-12 && d1[3].is_nan(), "m converted to mm: {d1:?}");
    assert_eq!(r.input_x_m_s2.as_ref().unwrap()[3], 0.4);
    assert!(b.summary().contains("r1: 4 samples at 100.0 Hz"));
}

#[test]
fn tables_and_columns_in_any_order_are_accepted() {
    // Runs before sensors, structure last, columns permuted.
    let parts: Vec<&str> = TOML.split("\n[").collect();
    let reordered =
        format!("{}\n[{}\n[{}\n[{}\n[{}", parts[0], parts[4], parts[3], parts[2], parts[1]);
    let run = "t,D1,A1,base_ax\n0,0.001,0.5,0.1\n0.01,0.002,0.6,0.2\n";
    let dir = make(&reordered, run);
    let b = read_bundle(dir.path()).unwrap();
    assert!((b.runs[0].sensor("A1").unwrap()[1] - 0.6 * 9.80665).abs() < 1e-12);
}

#[test]
fn written_bundle_reads_back_identically() {
    let dir = make(TOML, RUN);
    let b = read_bundle(dir.path()).unwrap();
    let out = tempfile::tempdir().unwrap();
    write_bundle(&b, out.path()).unwrap();
    let back = read_bundle(out.path()).unwrap();
    assert_eq!(back.manifest, b.manifest);
    let (x, y) = (&b.runs[0], &back.runs[0]);
    assert_eq!(x.input_x_m_s2, y.input_x_m_s2);
    for ((_, a), (_, c)) in x.sensors.iter().zip(&y.sensors) {
        for (u, v) in a.iter().zip(c) {
            assert!((u.is_nan() && v.is_nan()) || (u - v).abs() <= 1e-12 * u.abs(), "{u} {v}");
        }
    }
}

/// `wall_members` is optional (false), read when given, written back only
/// when true, named in the summary, and refused with its key when not a
/// boolean.
#[test]
fn wall_members_are_read_and_written_back() {
    let plain = read_bundle(make(TOML, RUN).path()).unwrap();
    assert!(!plain.manifest.structure.wall_members);
    assert!(!plain.summary().contains("wall lines"));
    let toml = TOML.replace("nominal_gap_mm = 19.0", "nominal_gap_mm = 19.0\nwall_members = true");
    let dir = make(&toml, RUN);
    let b = read_bundle(dir.path()).unwrap();
    assert!(b.manifest.structure.wall_members);
    assert!(b.summary().contains("gap 19 mm, members on the wall lines"), "{}", b.summary());
    let spec = crate::specimen::fe_spec(&b.manifest.structure, Default::default()).unwrap();
    assert!(spec.structure.wall_members);
    let out = tempfile::tempdir().unwrap();
    write_bundle(&b, out.path()).unwrap();
    assert_eq!(read_bundle(out.path()).unwrap().manifest, b.manifest);
    let written = |d: &Path| std::fs::read_to_string(d.join("bundle.toml")).unwrap();
    assert!(written(out.path()).contains("wall_members = true"));
    let plain_out = tempfile::tempdir().unwrap();
    write_bundle(&plain, plain_out.path()).unwrap();
    assert!(!written(plain_out.path()).contains("wall_members"));
    let e = refused(&toml.replace("wall_members = true", "wall_members = \"yes\""), RUN);
    assert!(e.contains("bundle.toml") && e.contains("wall_members"), "{e}");
}

/// `hanger_offset_m` is optional (0), read, written back only when not 0,
/// carried to the FE specimen, and refused with its key and the accepted
/// values when off the module, negative or not below the hanger spacing.
#[test]
fn hanger_offset_is_read_checked_and_written_back() {
    let toml =
        TOML.replace("nominal_gap_mm = 19.0", "nominal_gap_mm = 19.0\nhanger_offset_m = 0.6");
    let dir = make(&toml, RUN);
    let b = read_bundle(dir.path()).unwrap();
    assert_eq!(b.manifest.structure.hanger_offset_m, 0.6);
    let spec = crate::specimen::fe_spec(&b.manifest.structure, Default::default()).unwrap();
    assert_eq!(spec.structure.hanger_offset_m, 0.6);
    let out = tempfile::tempdir().unwrap();
    write_bundle(&b, out.path()).unwrap();
    assert_eq!(read_bundle(out.path()).unwrap().manifest, b.manifest);
    let plain = read_bundle(make(TOML, RUN).path()).unwrap();
    assert_eq!(plain.manifest.structure.hanger_offset_m, 0.0);
    let plain_out = tempfile::tempdir().unwrap();
    write_bundle(&plain, plain_out.path()).unwrap();
    let text = std::fs::read_to_string(plain_out.path().join("bundle.toml")).unwrap();
    assert!(!text.contains("hanger_offset_m"), "{text}");
    for bad in ["1.2", "0.3", "-0.6", "nan"] {
        let e = refused(
            &toml.replace("hanger_offset_m = 0.6", &format!("hanger_offset_m = {bad}")),
            RUN,
        );
        assert!(
            e.contains("structure.hanger_offset_m") && e.contains("hanger_spacing_m"),
            "{bad}: {e}"
        );
    }
}

#[test]
fn wrong_format_is_refused() {
    let e = refused(&TOML.replace("ceiling-measured/1", "ceiling-measured/2"), RUN);
    assert!(
        e.contains(
            "bundle.toml: format: \"ceiling-measured/2\": expected exactly \"ceiling-measured/1\""
        ),
        "{e}"
    );
}

#[test]
fn missing_required_key_is_refused() {
    let e = refused(&TOML.replace("module_m = 0.6\n", ""), RUN);
    assert!(e.contains("bundle.toml") && e.contains("missing field `module_m`"), "{e}");
}

#[test]
fn unknown_key_is_refused() {
    let e = refused(&TOML.replace("x_m = 1.2", "x_mm = 1.2"), RUN);
    assert!(e.contains("bundle.toml") && e.contains("unknown field `x_mm`"), "{e}");
}

#[test]
fn duplicate_ids_are_refused() {
    let e = refused(&TOML.replace("id = \"D1\"", "id = \"A1\""), &RUN.replace("D1", "A1"));
    assert!(e.contains("sensors[1].id: \"A1\" is used twice"), "{e}");
    let twice = format!("{TOML}\n[[runs]]\nid = \"r1\"\nfile = \"runs/r1.csv\"\ninput_x = \"base_ax\"\ninput_units = \"g\"\n");
    let e = refused(&twice, RUN);
    assert!(e.contains("runs[1].id: \"r1\" is used twice"), "{e}");
}

#[test]
fn sensor_outside_the_ceiling_is_refused() {
    let e = refused(&TOML.replace("x_m = 1.2", "x_m = 14.7"), RUN);
    assert!(e.contains("sensors[0].x_m: x = 14.7 m lies outside the ceiling (0 to 2.4 m)"), "{e}");
}

#[test]
fn missing_or_escaping_run_files_are_refused() {
    let e = refused(&TOML.replace("runs/r1.csv", "runs/r2.csv"), RUN);
    assert!(e.contains("runs[0].file: \"runs/r2.csv\": no such file in the bundle"), "{e}");
    let e = refused(&TOML.replace("runs/r1.csv", "../r1.csv"), RUN);
    assert!(
        e.contains("runs[0].file: \"../r1.csv\": expected a path relative to the bundle directory"),
        "{e}"
    );
    let e = refused(&TOML.replace("runs/r1.csv", "/etc/passwd"), RUN);
    assert!(e.contains("runs[0].file: \"/etc/passwd\""), "{e}");
}

#[test]
fn symlink_out_of_the_bundle_is_refused() {
    let dir = make(TOML, RUN);
    let outside = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(outside.path(), RUN).unwrap();
    std::fs::remove_file(dir.path().join("runs/r1.csv")).unwrap();
    std::os::unix::fs::symlink(outside.path(), dir.path().join("runs/r1.csv")).unwrap();
    let e = read_bundle(dir.path()).unwrap_err().to_string();
    assert!(e.contains("resolves outside the bundle directory"), "{e}");
}

#[test]
fn non_monotonic_time_is_refused() {
    let e = refused(TOML, &RUN.replace("0.02,0.3", "0.005,0.3"));
    assert!(
        e.contains("runs/r1.csv:5: t = 0.005 after 0.01: time must be strictly increasing"),
        "{e}"
    );
}

#[test]
fn non_uniform_time_is_refused() {
    let e = refused(TOML, &RUN.replace("0.02,0.3", "0.021,0.3"));
    assert!(e.contains("runs/r1.csv:") && e.contains("expected a uniform"), "{e}");
}

#[test]
fn tiny_jitter_is_tolerated() {
    let dir = make(TOML, &RUN.replace("0.02,0.3", "0.0200000000005,0.3"));
    read_bundle(dir.path()).unwrap();
}

#[test]
fn wrong_field_count_is_refused() {
    let e = refused(TOML, &RUN.replace("0.01,0.2,,0.002", "0.01,0.2,0.002"));
    assert!(e.contains("runs/r1.csv:4: expected 4 fields, found 3"), "{e}");
    let e = refused(TOML, &RUN.replace("0.01,0.2,,0.002", "0.01,0.2,,0.002,7"));
    assert!(e.contains("runs/r1.csv:4: expected 4 fields, found more"), "{e}");
}

#[test]
fn non_numeric_text_is_refused() {
    let e = refused(TOML, &RUN.replace("0.5,0.001", "abc,0.001"));
    assert!(e.contains("runs/r1.csv:3: column \"A1\": \"abc\" is not a number"), "{e}");
}

#[test]
fn input_gap_is_refused() {
    let e = refused(TOML, &RUN.replace("0.01,0.2,", "0.01,,"));
    assert!(e.contains("runs/r1.csv:4: input column \"base_ax\" has a gap"), "{e}");
}

#[test]
fn unknown_column_is_refused() {
    let e = refused(TOML, &RUN.replace("t,base_ax,A1,D1", "t,base_ax,A1,D2"));
    assert!(
        e.contains(
            "runs/r1.csv:2: column 4 \"D2\" is neither t, an input of run r1 nor a listed sensor"
        ),
        "{e}"
    );
}

#[test]
fn missing_input_column_is_refused() {
    let e = refused(&TOML.replace("input_x = \"base_ax\"", "input_x = \"floor_ax\""), RUN);
    assert!(e.contains("column 2 \"base_ax\" is neither"), "{e}");
}

#[test]
fn nul_byte_is_refused() {
    let e = refused(TOML, &RUN.replace("0.5", "0.\u{0}5"));
    assert!(e.contains("runs/r1.csv:3: NUL byte"), "{e}");
    let e = refused(&TOML.replace("t1", "t\u{0}1"), RUN);
    assert!(e.contains("bundle.toml:3: NUL byte"), "{e}");
}

#[test]
fn huge_line_and_too_many_fields_are_refused_within_bounds() {
    let long = format!("t,base_ax\n0,{}\n", "1".repeat(3 << 20));
    let e = refused(TOML, &long);
    assert!(e.contains("runs/r1.csv:2: line longer than the limit of 1048576 bytes"), "{e}");
    let wide = format!("t,{}\n", vec!["x"; 10_000].join(","));
    let e = refused(TOML, &wide);
    assert!(e.contains("10001 columns: more than the limit of 4096"), "{e}");
}

#[test]
fn ten_gigabyte_run_file_is_refused_without_reading_it() {
    let dir = make(TOML, RUN);
    let f = std::fs::OpenOptions::new().write(true).open(dir.path().join("runs/r1.csv")).unwrap();
    f.set_len(10 << 30).unwrap(); // sparse: no disk used
    let e = read_bundle(dir.path()).unwrap_err().to_string();
    assert!(e.contains("runs/r1.csv: larger than the limit of"), "{e}");
}

#[test]
fn missing_bundle_toml_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let e = read_bundle(dir.path()).unwrap_err().to_string();
    assert!(e.contains("bundle.toml: missing"), "{e}");
}

#[test]
fn modal_csv_is_checked() {
    let dir = make(TOML, RUN);
    std::fs::write(dir.path().join("modal.csv"), "mode,freq_hz,std_hz\n2,8.1,0.006\n1,7.5,\n")
        .unwrap();
    let b = read_bundle(dir.path()).unwrap();
    let m = b.modal.unwrap();
    assert_eq!((m[0].mode, m[0].std_hz, m[1].std_hz), (1, None, Some(0.006)));
    std::fs::write(dir.path().join("modal.csv"), "mode,freq_hz,std_hz\n1,abc,0\n").unwrap();
    let e = read_bundle(dir.path()).unwrap_err().to_string();
    assert!(e.contains("modal.csv:2: freq_hz \"abc\" is not a number"), "{e}");
}

#[test]
fn gap_required_unless_fixed() {
    let e = refused(&TOML.replace("nominal_gap_mm = 19.0\n", ""), RUN);
    assert!(
        e.contains("structure.nominal_gap_mm: missing: required when boundary = \"semi-free\""),
        "{e}"
    );
    let dir = make(&TOML.replace("nominal_gap_mm = 19.0\n", "").replace("semi-free", "fixed"), RUN);
    read_bundle(dir.path()).unwrap();
}

fn mutate(bytes: &[u8], edits: &[(usize, u8, u8)]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for &(pos, op, val) in edits {
        if out.is_empty() {
            out.push(val);
            continue;
        }
        let p = pos % out.len();
        match op % 4 {
            0 => out[p] = val,
            1 => out.insert(p, val),
            2 => {
                out.remove(p);
            }
            _ => out.truncate(p),
        }
    }
    out
}

fn read_raw(toml: &[u8], run: &[u8]) -> Result<Bundle, BundleError> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("runs")).unwrap();
    std::fs::write(dir.path().join("bundle.toml"), toml).unwrap();
    std::fs::write(dir.path().join("runs/r1.csv"), run).unwrap();
    read_bundle(Path::new(dir.path()))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

    /// Fuzz: random byte edits of a valid bundle never panic; the reader
    /// either accepts or refuses with a message naming a file.
    #[test]
    fn mutated_bundles_never_panic(
        toml_edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 0..6),
        run_edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 0..6),
    ) {
        let toml = mutate(TOML.as_bytes(), &toml_edits);
        let run = mutate(RUN.as_bytes(), &run_edits);
        if let Err(e) = read_raw(&toml, &run) {
            let msg = e.to_string();
            prop_assert!(msg.contains("bundle.toml") || msg.contains("r1.csv"), "{}", msg);
        }
    }
}
