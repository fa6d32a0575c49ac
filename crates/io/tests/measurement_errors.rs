//! Bad measurement files are errors that name the file, line and column;
//! good files in both layouts are read, including the reference files.

use paperbsdf_io::measurement::{parse_measurement, read_measurement, Kind};

mod common;

fn err(text: &str) -> String {
    parse_measurement(text, "m.csv").unwrap_err().to_string()
}

#[test]
fn empty_file() {
    let e = err("");
    assert!(e.starts_with("m.csv:") && e.contains("empty"), "{e}");
    let e = err("# only a comment\nkind,theta_i_deg,theta_o_deg,f\n");
    assert!(e.contains("empty") && e.contains("no measurements"), "{e}");
}

#[test]
fn non_number() {
    let e = err("kind,theta_i_deg,theta_o_deg,f\nR,0,10,0.5\nR,0,x20,0.5\n");
    assert!(
        e.starts_with("m.csv:3:3:") && e.contains("theta_o_deg") && e.contains("x20"),
        "{e}"
    );
    let e = err("kind,theta_i_deg,theta_o_deg,f\nR,0,10,nan\n");
    assert!(e.starts_with("m.csv:2:4:") && e.contains("`f`"), "{e}");
}

#[test]
fn angle_out_of_range() {
    let e = err("kind,theta_i_deg,theta_o_deg,f\nR,95,10,0.5\n");
    assert!(
        e.starts_with("m.csv:2:2:") && e.contains("95") && e.contains("[-90, 90]"),
        "{e}"
    );
    let e = err("# c\nkind,theta_i_deg,theta_o_deg,f\nT,0,-90.5,0.5\n");
    assert!(e.starts_with("m.csv:3:3:") && e.contains("-90.5"), "{e}");
}

#[test]
fn negative_value_and_stderr() {
    let e = err("kind,theta_i_deg,theta_o_deg,f,stderr\nR,0,10,-0.5,0.1\n");
    assert!(e.starts_with("m.csv:2:4:") && e.contains("negative"), "{e}");
    let e = err("kind,theta_i_deg,theta_o_deg,r,g,b\nR,0,10,0.5,0.2,-1e-3\n");
    assert!(e.starts_with("m.csv:2:6:") && e.contains("negative"), "{e}");
    let e = err("kind,theta_i_deg,theta_o_deg,f,stderr\nR,0,10,0.5,-0.1\n");
    assert!(e.starts_with("m.csv:2:5:") && e.contains("standard error"), "{e}");
}

#[test]
fn unknown_kind() {
    let e = err("kind,theta_i_deg,theta_o_deg,f\nX,0,10,0.5\n");
    assert!(e.starts_with("m.csv:2:1:") && e.contains("unknown kind `X`"), "{e}");
}

#[test]
fn missing_columns_and_short_rows() {
    let e = err("kind,theta_i,theta_o,f\nR,0,10,0.5\n");
    assert!(
        e.starts_with("m.csv:1:") && e.contains("kind,theta_i_deg,theta_o_deg"),
        "{e}"
    );
    let e = err("kind,theta_i_deg,theta_o_deg,value\nR,0,10,0.5\n");
    assert!(e.contains("`f` or `r,g,b`"), "{e}");
    let e = err("kind,theta_i_deg,theta_o_deg,f\nR,0,10\n");
    assert!(e.starts_with("m.csv:2:") && e.contains("3 fields"), "{e}");
    let e = read_measurement("/nonexistent/file.csv").unwrap_err().to_string();
    assert!(e.contains("/nonexistent/file.csv"), "{e}");
}

#[test]
fn general_layout() {
    let s = 0.5f64.sqrt();
    let text = format!(
        "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z,r,g,b,stderr\n{s},0,{s},-{s},0,{s},0.1,0.2,0.3,0.01\n0,0,1,0,0,-1,1,1,1,0\n"
    );
    let m = parse_measurement(&text, "g.csv").unwrap();
    assert!(m.is_rgb && !m.in_plane);
    assert_eq!(m.points[0].kind, Kind::R);
    assert!((m.points[0].theta_i - 45.0).abs() < 1e-9);
    assert_eq!(m.points[1].kind, Kind::T);
    assert_eq!(m.points[0].f.0, [0.1, 0.2, 0.3]);
    let e = err("wi_x,wi_y,wi_z,wo_x,wo_y,wo_z,f\n1,0,1,0,0,1,0.5\n");
    assert!(e.starts_with("m.csv:2:1:") && e.contains("unit vector"), "{e}");
}

#[test]
fn reference_files_read_with_thickness_from_header() {
    for (f, d) in [("devA.csv", 0.1), ("devB.csv", 0.25)] {
        let p = common::reference(f);
        let m = read_measurement(p.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.thickness, Some(d));
        assert_eq!(m.points.len(), 72);
        assert!(m.points.iter().all(|p| p.stderr.is_some()));
        assert_eq!(m.theta_i_values(), vec![0.0, 30.0, 60.0, 75.0]);
    }
    let m = parse_measurement(
        "# thickness: 0.12 mm\nkind,theta_i_deg,theta_o_deg,f,samples\nR,0,0,1,77\n",
        "t",
    )
    .unwrap();
    assert_eq!(m.thickness, Some(0.12));
}
