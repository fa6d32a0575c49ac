//! Property-based fuzzing (proptest) of the io crate's parsers: parameter
//! files (JSON and TOML), direction CSVs, measurement CSVs and angle lists. Arbitrary bytes and
//! structured near-valid inputs must give `Ok` or an error naming the origin,
//! never a panic, and never a large allocation (a counting allocator records
//! the largest single request; inputs are at most a few kB, so any request
//! above 16 MiB is unbounded growth).
//!
//! Case counts are chosen so the whole file runs in a few seconds on 2 cores.

use paperbsdf_core::PaperParams;
use paperbsdf_io::angles::parse_angles;
use paperbsdf_io::dirs::parse_dirs;
use paperbsdf_io::measurement::{parse_measurement, read_measurement};
use paperbsdf_io::params::parse_text;
use proptest::prelude::*;

#[path = "common/largest_alloc.rs"]
mod largest_alloc;

const ALLOC_LIMIT: usize = 16 << 20;

fn bounded() {
    largest_alloc::assert_bounded(ALLOC_LIMIT);
}

/// A text that is mostly valid: fragments of the format mixed with noise.
fn mixed_text(fragments: &'static [&'static str]) -> impl Strategy<Value = String> {
    prop::collection::vec(
        prop_oneof![
            3 => prop::sample::select(fragments).prop_map(str::to_string),
            1 => "[ -~\\n\\t\u{feff}\u{e9}]{0,8}",
            1 => prop::num::f64::ANY.prop_map(|x| x.to_string()),
        ],
        0..40,
    )
    .prop_map(|v| v.concat())
}

const JSON_BITS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"d\"",
    "\"sigma_a\"",
    "\"sigma_s\"",
    "\"g_f\"",
    "\"g_b\"",
    "\"w_b\"",
    "\"eta_f\"",
    "\"eta_b\"",
    "\"m_f\"",
    "\"m_b\"",
    "\"dist_f\"",
    "\"dist_b\"",
    "\"ggx\"",
    "\"beckmann\"",
    "0.1",
    "1e308",
    "-1",
    "[1,2,3]",
    "[1,2]",
    "null",
    "true",
    "\"",
    "\\",
    "\u{feff}",
];
const TOML_BITS: &[&str] = &[
    "d",
    "sigma_a",
    "sigma_s",
    "g_f",
    "w_b",
    "eta_f",
    "m_b",
    "dist_f",
    " = ",
    "\n",
    "\"ggx\"",
    "0.3",
    "[1, 2, 3]",
    "[",
    "]",
    "[table]",
    "inf",
    "nan",
    "'",
    "\"",
    "#",
    "\u{feff}",
];
const CSV_BITS: &[&str] = &[
    "wi_x",
    "wi_y",
    "wi_z",
    "wo_x",
    "wo_y",
    "wo_z",
    "id",
    ",",
    "\n",
    "\r\n",
    "#",
    "0",
    "1",
    "-1",
    "0.7071067811865476",
    "nan",
    "inf",
    "1e400",
    " ",
    "\u{feff}",
];
const MEASUREMENT_BITS: &[&str] = &[
    "kind",
    "theta_i_deg",
    "theta_o_deg",
    "f",
    "r",
    "g",
    "b",
    "stderr",
    "stderr_r",
    "wi_x",
    "wi_y",
    "wi_z",
    "wo_x",
    "wo_y",
    "wo_z",
    ",",
    "\n",
    "\r\n",
    "# params: ",
    "# thickness: ",
    "{\"d\":0.1}",
    "R",
    "T",
    "0",
    "30",
    "-45",
    "90",
    "0.5",
    "1e300",
    "nan",
    "-1",
    "#",
    " ",
    "\u{feff}",
];

const GOOD: &str = r#"{"d":0.1,"sigma_a":0.6,"sigma_s":[120,110,100],"g_f":0.85,"g_b":-0.4,"w_b":0.15,"eta_f":1.45,"eta_b":1.45,"m_f":0.35,"m_b":0.35,"dist_f":"ggx","dist_b":"ggx"}"#;

/// Issue 16: with a BOM the first comment line of a measurement file was taken for the header.
#[test]
fn measurement_byte_order_mark_is_accepted() {
    let body = "# thickness: 0.1\nkind,theta_i_deg,theta_o_deg,f\nR,30,-30,0.5\nT,30,10,0.25\n";
    let plain = parse_measurement(body, "m.csv").unwrap();
    let bom = parse_measurement(&format!("\u{feff}{body}"), "m.csv").unwrap();
    assert_eq!(bom.points, plain.points);
    assert_eq!(bom.thickness, Some(0.1));
    // From a file too.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bom.csv");
    std::fs::write(&p, format!("\u{feff}{body}")).unwrap();
    let m = read_measurement(p.to_str().unwrap()).unwrap();
    assert_eq!(m.points.len(), 2);
    assert_eq!(m.points[0].line, 3);
    // Header first, with a BOM.
    let m = parse_measurement("\u{feff}kind,theta_i_deg,theta_o_deg,f\nR,0,0,1\n", "m.csv").unwrap();
    assert_eq!(m.points.len(), 1);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn params_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..512), toml in any::<bool>()) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = parse_text::<PaperParams>(&text, "fuzz", toml).map_err(|e| assert!(e.to_string().starts_with("fuzz:"), "{e}"));
        bounded();
    }

    #[test]
    fn params_from_near_valid_json(text in mixed_text(JSON_BITS)) {
        match parse_text::<PaperParams>(&text, "fuzz.json", false) {
            Ok(p) => { let _ = p.validate(); }
            Err(e) => assert!(e.to_string().starts_with("fuzz.json:"), "{e}"),
        }
        bounded();
    }

    #[test]
    fn params_from_near_valid_toml(text in mixed_text(TOML_BITS)) {
        match parse_text::<PaperParams>(&text, "fuzz.toml", true) {
            Ok(p) => { let _ = p.validate(); }
            Err(e) => assert!(e.to_string().starts_with("fuzz.toml:"), "{e}"),
        }
        bounded();
    }

    /// Structured values: every parameter replaced by an arbitrary number
    /// (including non-finite ones and out-of-range values) or a wrong type.
    #[test]
    fn params_with_arbitrary_values(key in prop::sample::select(&["d","sigma_a","sigma_s","g_f","g_b","w_b","eta_f","eta_b","m_f","m_b","dist_f","dist_b"][..]),
                                    value in prop_oneof![
                                        prop::num::f64::ANY.prop_map(|x| format!("{x:e}")),
                                        prop::collection::vec(prop::num::f64::NORMAL, 0..5).prop_map(|v| format!("{v:?}")),
                                        "\"[a-z]{0,6}\"",
                                        Just("null".to_string()),
                                        Just("{}".to_string()),
                                    ]) {
        let v: serde_json::Value = serde_json::from_str(GOOD).unwrap();
        let mut m = v.as_object().unwrap().clone();
        let text = match serde_json::from_str::<serde_json::Value>(&value) {
            Ok(x) => { m.insert(key.to_string(), x); serde_json::to_string(&m).unwrap() }
            // Not JSON (e.g. `inf`): splice the text in as written.
            Err(_) => GOOD.replacen(&format!("\"{key}\":"), &format!("\"{key}\":{value},\"x_{key}\":"), 1),
        };
        match parse_text::<PaperParams>(&text, "<inline>", false) {
            Ok(p) => {
                if let Err(e) = p.validate() {
                    assert!(!e.name().is_empty(), "a range error names its parameter");
                }
            }
            Err(e) => assert!(e.to_string().starts_with("<inline>:"), "{e}"),
        }
        bounded();
    }

    #[test]
    fn dirs_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        if let Err(e) = parse_dirs(&text, "fuzz.csv") {
            assert!(e.to_string().starts_with("fuzz.csv"), "{e}");
        }
        bounded();
    }

    #[test]
    fn dirs_from_near_valid_csv(text in mixed_text(CSV_BITS)) {
        match parse_dirs(&text, "fuzz.csv") {
            Ok(f) => for r in &f.rows {
                // Whatever was accepted is a pair of finite unit vectors.
                assert!(r.wi.is_finite() && r.wo.is_finite());
                assert!((r.wi.length() - 1.0).abs() < 1e-9 && (r.wo.length() - 1.0).abs() < 1e-9);
            },
            Err(e) => assert!(e.to_string().starts_with("fuzz.csv"), "{e}"),
        }
        bounded();
    }

    /// Structured rows: arbitrary numbers in a valid header layout.
    #[test]
    fn dirs_with_arbitrary_numbers(rows in prop::collection::vec(prop::array::uniform6(prop::num::f64::ANY), 0..20)) {
        let mut text = String::from("wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n");
        for r in &rows {
            text.push_str(&r.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(","));
            text.push('\n');
        }
        match parse_dirs(&text, "fuzz.csv") {
            Ok(f) => assert_eq!(f.rows.len(), rows.len()),
            Err(e) => assert!(e.to_string().contains("fuzz.csv:"), "{e}"),
        }
        bounded();
    }

    /// Angle lists: arbitrary text and arbitrary FROM:TO:STEP numbers; the
    /// result is never longer than the limit, and every angle is finite.
    #[test]
    fn angle_lists(text in "[-0-9.:e a-z]{0,24}",
                   from in prop::num::f64::ANY, to in prop::num::f64::ANY, step in prop::num::f64::ANY,
                   limit in 1usize..5000) {
        for s in [text.clone(), format!("{from}:{to}:{step}"), format!("{from:e}:{to:e}:{step:e}")] {
            match parse_angles(&s, "--theta-o", limit) {
                Ok(v) => {
                    assert!(!v.is_empty() && v.len() <= limit, "{s}: {} angles", v.len());
                    assert!(v.iter().all(|a| a.is_finite()), "{s}");
                }
                Err(e) => assert!(e.0.contains(&format!("`{s}`")), "the error quotes the input: {}", e.0),
            }
        }
        bounded();
    }

    #[test]
    fn measurement_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        if let Err(e) = parse_measurement(&text, "fuzz.csv") {
            assert!(e.to_string().starts_with("fuzz.csv"), "{e}");
        }
        bounded();
    }

    #[test]
    fn measurement_from_near_valid_text(parts in prop::collection::vec(prop_oneof![
        4 => prop::sample::select(MEASUREMENT_BITS).prop_map(str::to_string),
        1 => "[ -~\\n]{0,6}",
        1 => prop::num::f64::ANY.prop_map(|x| x.to_string()),
    ], 0..60)) {
        let text = parts.concat();
        match parse_measurement(&text, "fuzz.csv") {
            Ok(m) => for p in &m.points {
                assert!(p.f.0.iter().all(|v| v.is_finite()), "accepted a non-finite value: {text}");
                assert!(p.wi.is_finite() && p.wo.is_finite());
            },
            Err(e) => assert!(e.to_string().starts_with("fuzz.csv"), "{e}"),
        }
        bounded();
    }

    /// Structured rows: arbitrary numbers under a valid in-plane header.
    #[test]
    fn measurement_in_plane_rows_with_arbitrary_numbers(rows in prop::collection::vec(
        (any::<bool>(), prop::num::f64::ANY, prop::num::f64::ANY, prop::num::f64::ANY), 0..20)) {
        let mut text = String::from("kind,theta_i_deg,theta_o_deg,f\n");
        for (r, ti, to, f) in &rows {
            text.push_str(&format!("{},{ti},{to},{f}\n", if *r { "R" } else { "T" }));
        }
        match parse_measurement(&text, "fuzz.csv") {
            Ok(m) => assert_eq!(m.points.len(), rows.len()),
            Err(e) => assert!(e.to_string().starts_with("fuzz.csv:"), "{e}"),
        }
        bounded();
    }
}
