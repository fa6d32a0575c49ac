//! Measurement CSVs: a UTF-8 byte-order mark is accepted (issue 16), and
//! property-based fuzzing (proptest) of the reader: arbitrary bytes and
//! structured near-valid files give `Ok` or an error naming the file, never a
//! panic and never a large allocation (a counting allocator records the largest
//! single request; any request above 16 MiB from inputs of a few kB is
//! unbounded growth). A few seconds on 2 cores.

use paperbsdf_fit::{parse_measurement, read_measurement};
use proptest::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Largest;
static LARGEST: AtomicUsize = AtomicUsize::new(0);
unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        LARGEST.fetch_max(l.size(), Ordering::Relaxed);
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        LARGEST.fetch_max(n, Ordering::Relaxed);
        System.realloc(p, l, n)
    }
}
#[global_allocator]
static A: Largest = Largest;

fn bounded() {
    let m = LARGEST.load(Ordering::Relaxed);
    assert!(m < 16 << 20, "an allocation of {m} bytes");
}

/// Issue 16: with a BOM the first comment line was taken for the header.
#[test]
fn byte_order_mark_is_accepted() {
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

const BITS: &[&str] = &[
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

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        if let Err(e) = parse_measurement(&text, "fuzz.csv") {
            assert!(e.to_string().starts_with("fuzz.csv"), "{e}");
        }
        bounded();
    }

    #[test]
    fn near_valid_text(parts in prop::collection::vec(prop_oneof![
        4 => prop::sample::select(BITS).prop_map(str::to_string),
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
    fn in_plane_rows_with_arbitrary_numbers(rows in prop::collection::vec(
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
