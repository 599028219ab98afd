//! Bundle input tests: the CSV forms a spreadsheet writes (byte-order mark,
//! CRLF, quotes) and the bounds on what a bundle may reference (files
//! confined to the folder and regular, memory per bundle, absurd values,
//! `modal.csv`'s duplicate check).

use super::tests::make;
use super::*;
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

[[runs]]
id = "r1"
file = "runs/r1.csv"
input_x = "base_ax"
input_units = "m/s2"
"#;

const RUN: &str = "t,base_ax,A1\n0.0,0.1,0.5\n0.01,0.2,\n0.02,0.3,1.0\n";

fn refused(dir: &Path) -> String {
    read_bundle(dir).expect_err("bundle should be refused").to_string()
}

/// The run of `RUN`, read from a bundle whose run file is `run`.
fn read_as(run: &str) -> RunData {
    let dir = make(TOML, run);
    read_bundle(dir.path()).unwrap().runs.remove(0)
}

#[test]
fn run_file_with_a_byte_order_mark_is_read() {
    assert_eq!(read_as(&format!("\u{feff}{RUN}")).clone_nan_free(), read_as(RUN).clone_nan_free());
}

#[test]
fn run_file_with_crlf_line_ends_is_read() {
    let crlf = format!("# exported\r\n{}", RUN.replace('\n', "\r\n"));
    assert_eq!(read_as(&crlf).clone_nan_free(), read_as(RUN).clone_nan_free());
}

#[test]
fn run_file_with_a_quoted_header_is_read() {
    let quoted = RUN.replace("t,base_ax,A1", "\"t\",\"base_ax\",\"A1\"");
    assert_eq!(read_as(&quoted).clone_nan_free(), read_as(RUN).clone_nan_free());
}

impl RunData {
    /// The run with NaN readings as a sentinel, so runs compare with `==`.
    fn clone_nan_free(&self) -> RunData {
        let mut r = self.clone();
        for (_, v) in &mut r.sensors {
            v.iter_mut().filter(|x| x.is_nan()).for_each(|x| *x = -1e300);
        }
        r
    }
}

#[test]
fn symlinked_modal_csv_out_of_the_bundle_is_refused() {
    let dir = make(TOML, RUN);
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("modal.csv")).unwrap();
    let e = refused(dir.path());
    assert!(e.ends_with("modal.csv: resolves outside the bundle directory"), "{e}");
}

#[test]
fn symlinked_bundle_toml_out_of_the_bundle_is_refused() {
    let dir = make(TOML, RUN);
    let outside = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(outside.path(), TOML).unwrap();
    std::fs::remove_file(dir.path().join("bundle.toml")).unwrap();
    std::os::unix::fs::symlink(outside.path(), dir.path().join("bundle.toml")).unwrap();
    let e = refused(dir.path());
    assert!(e.ends_with("bundle.toml: resolves outside the bundle directory"), "{e}");
}

/// Makes a FIFO at `path` (reading one would block until a writer comes).
fn mkfifo(path: &Path) {
    let ok = std::process::Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

#[test]
fn fifo_run_file_and_modal_csv_are_refused_without_blocking() {
    let dir = make(TOML, RUN);
    std::fs::remove_file(dir.path().join("runs/r1.csv")).unwrap();
    mkfifo(&dir.path().join("runs/r1.csv"));
    let e = refused(dir.path());
    assert!(e.contains("runs[0].file: \"runs/r1.csv\": not a regular file"), "{e}");
    let dir = make(TOML, RUN);
    mkfifo(&dir.path().join("modal.csv"));
    let e = refused(dir.path());
    assert!(e.contains("modal.csv: not a regular file (a directory, FIFO"), "{e}");
}

#[test]
fn runs_naming_one_file_share_the_bundles_memory_bound() {
    let mut toml = TOML.to_string();
    for k in 2..=20 {
        toml += &format!(
            "\n[[runs]]\nid = \"r{k}\"\nfile = \"runs/r1.csv\"\ninput_x = \"base_ax\"\ninput_units = \"m/s2\"\n"
        );
    }
    let dir = make(&toml, RUN);
    // 20 runs of 3 rows x 3 columns hold 180 numbers; 100 allowed.
    let limits = Limits { max_values: 100, ..Limits::default() };
    let e = read_bundle_with(dir.path(), &limits).unwrap_err().to_string();
    assert!(e.contains("runs/r1.csv:2: more than the 1 numbers left of the bundle's limit"), "{e}");
    let limits = Limits { max_values: 180, ..Limits::default() };
    assert_eq!(read_bundle_with(dir.path(), &limits).unwrap().runs.len(), 20);
}

#[test]
fn absurd_times_are_refused_with_the_range() {
    let dir = make(TOML, &RUN.replace("0.02,0.3", "1.7e308,0.3"));
    let e = refused(dir.path());
    assert!(
        e.contains("runs/r1.csv:4: column \"t\": 1.7e308: outside the accepted range -1000000 to 1000000 s"),
        "{e}"
    );
    let dir = make(TOML, "t,base_ax\n0,0.1\n1e-300,0.2\n2e-300,0.3\n");
    let e = refused(dir.path());
    assert!(
        e.contains("runs/r1.csv: time step dt = 1e-300: outside the accepted range 1e-6 to 10 s"),
        "{e}"
    );
}

#[test]
fn absurd_structure_is_refused_with_the_key_and_range() {
    let dir = make(&TOML.replace("length_x_m = 2.4", "length_x_m = 6e11"), RUN);
    let e = refused(dir.path());
    assert!(
        e.contains(
            "bundle.toml: structure.length_x_m: 6e11: outside the accepted range 0 to 100 m"
        ),
        "{e}"
    );
    let dir = make(&TOML.replace("nominal_gap_mm = 19.0", "nominal_gap_mm = 1e5"), RUN);
    let e = refused(dir.path());
    assert!(e.contains("structure.nominal_gap_mm: 100000: outside the accepted range"), "{e}");
}

#[test]
fn modal_csv_duplicates_and_absurd_frequencies_are_refused() {
    let dir = make(TOML, RUN);
    let mut modal = String::from("\u{feff}mode,freq_hz,std_hz\r\n");
    for k in 1..=20_000 {
        modal += &format!("{k},{},0\r\n", 1.0 + k as f64 * 1e-3);
    }
    modal += "7,3.0,0\r\n";
    std::fs::write(dir.path().join("modal.csv"), &modal).unwrap();
    let e = refused(dir.path());
    assert!(e.contains("modal.csv:20002: mode 7 listed twice"), "{e}");
    std::fs::write(dir.path().join("modal.csv"), "mode,freq_hz,std_hz\n1,2e9,0\n").unwrap();
    let e = refused(dir.path());
    assert!(
        e.contains("modal.csv:2: freq_hz 2e9: outside the accepted range 0 to 10000 Hz"),
        "{e}"
    );
}
