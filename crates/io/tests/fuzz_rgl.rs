//! Property-based fuzzing (proptest) of the RGL `.bsdf` reader
//! ([`MeasuredBsdf::from_bytes`]): arbitrary bytes, and the real files of
//! `data/reference/rgl` with header fields mutated (field count, name lengths,
//! ranks, element types, offsets and shape dimensions set to edge values),
//! huge declared dimensions, cuts at random offsets, corrupted bytes anywhere,
//! and small well-formed files of arbitrary shapes. Every input gives `Ok` (then
//! evaluating it must not panic) or an error that names the file; nothing
//! panics, and nothing allocates more than a few times the input's size: a
//! counting allocator records each thread's largest single request, so a
//! declared size larger than the file that were allocated before being checked
//! fails the test (it would be gigabytes, here at most 4 x the file + 1 MiB).
//!
//! Case counts are chosen so the whole file runs in a few seconds on 2 cores
//! (a full parse of a 660 kB file is the costly case).

use paperbsdf_core::DVec3;
use paperbsdf_io::rgl::tensor::{DType, TensorFile};
use paperbsdf_io::MeasuredBsdf;
use proptest::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::OnceLock;

struct Peak;
thread_local! {
    static PEAK: Cell<usize> = const { Cell::new(0) };
}
fn note(n: usize) {
    let _ = PEAK.try_with(|p| p.set(p.get().max(n)));
}
unsafe impl GlobalAlloc for Peak {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        note(l.size());
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        note(n);
        System.realloc(p, l, n)
    }
}
#[global_allocator]
static A: Peak = Peak;

const ORIGIN: &str = "fuzz.bsdf";

/// Parses `bytes` as a file named [`ORIGIN`] and checks the outcome: an
/// accepted file evaluates without panic, a refused one has an error that
/// names the file and says something; the largest allocation of this thread
/// during the parse is below 4 x the input + 1 MiB. Returns the error text.
fn check(bytes: Vec<u8>) -> Option<String> {
    let limit = 4 * bytes.len() + (1 << 20);
    PEAK.with(|p| p.set(0));
    let r = MeasuredBsdf::from_bytes(bytes, ORIGIN);
    let peak = PEAK.with(|p| p.get());
    assert!(peak <= limit, "an allocation of {peak} bytes (limit {limit})");
    match r {
        Ok(m) => {
            for (wi, wo) in [
                (DVec3::new(0.2, 0.1, 0.97), DVec3::new(-0.3, 0.0, 0.95)),
                (DVec3::Z, DVec3::Z),
                (DVec3::new(0.99, 0.0, 0.05), DVec3::new(-0.99, 0.05, 0.05)),
                (DVec3::new(0.0, -0.6, 0.8), DVec3::new(0.0, 0.6, 0.8)),
            ] {
                let _ = m.eval_raw(wi.normalize(), wo.normalize());
            }
            None
        }
        Err(e) => {
            let e = e.to_string();
            let prefix = format!("{ORIGIN}: ");
            assert!(e.starts_with(&prefix) && e.len() > prefix.len() + 5, "{e}");
            Some(e)
        }
    }
}

fn file(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/reference/rgl")
        .join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The reference files (satin: isotropic, 8 incident elevations; car paint).
fn real(which: bool) -> &'static [u8] {
    static SATIN: OnceLock<Vec<u8>> = OnceLock::new();
    static PAINT: OnceLock<Vec<u8>> = OnceLock::new();
    if which {
        SATIN.get_or_init(|| file("satin_rosaline_rgb.bsdf"))
    } else {
        PAINT.get_or_init(|| file("cc_ibiza_sunset_rgb.bsdf"))
    }
}

/// What a header item of a tensor file is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Item {
    Version,
    FieldCount,
    NameLen(usize),
    Name(usize),
    Rank(usize),
    Type(usize),
    Offset(usize),
    /// Field, dimension.
    Dim(usize, usize),
}

/// A field as the real file declares it.
#[derive(Clone, Debug)]
struct Decl {
    name: String,
    size: u64,
    offset: u64,
    dims: Vec<u64>,
}

/// The header items of a tensor file (item, byte position, width) and its fields.
type Header = (Vec<(Item, usize, usize)>, Vec<Decl>);

/// The header items of a well-formed tensor file: (item, byte position,
/// width), and its fields. An independent reading of the layout (see
/// `paperbsdf_io::rgl::tensor`), for placing mutations.
fn layout(b: &[u8]) -> Header {
    let u16_at = |p: usize| u16::from_le_bytes([b[p], b[p + 1]]) as usize;
    let u64_at = |p: usize| u64::from_le_bytes(b[p..p + 8].try_into().unwrap());
    let mut items = vec![(Item::Version, 12, 2), (Item::FieldCount, 14, 4)];
    let n = u32::from_le_bytes(b[14..18].try_into().unwrap()) as usize;
    let mut decls = Vec::new();
    let mut p = 18;
    for k in 0..n {
        let len = u16_at(p);
        items.push((Item::NameLen(k), p, 2));
        items.push((Item::Name(k), p + 2, len));
        let name = String::from_utf8(b[p + 2..p + 2 + len].to_vec()).unwrap();
        p += 2 + len;
        let rank = u16_at(p);
        items.push((Item::Rank(k), p, 2));
        items.push((Item::Type(k), p + 2, 1));
        let size = match b[p + 2] {
            1 | 2 => 1,
            3 | 4 | 9 => 2,
            5 | 6 | 10 => 4,
            _ => 8,
        };
        items.push((Item::Offset(k), p + 3, 8));
        let offset = u64_at(p + 3);
        p += 11;
        let mut dims = Vec::new();
        for j in 0..rank {
            items.push((Item::Dim(k, j), p, 8));
            dims.push(u64_at(p));
            p += 8;
        }
        decls.push(Decl {
            name,
            size,
            offset,
            dims,
        });
    }
    (items, decls)
}

fn real_layout(which: bool) -> &'static Header {
    static SATIN: OnceLock<Header> = OnceLock::new();
    static PAINT: OnceLock<Header> = OnceLock::new();
    let cell = if which { &SATIN } else { &PAINT };
    cell.get_or_init(|| layout(real(which)))
}

/// Writes `v` little-endian into the `width` bytes at `pos` (truncated, or
/// repeated for a longer item such as a name).
fn poke(b: &mut [u8], pos: usize, width: usize, v: u64) {
    let le = v.to_le_bytes();
    for i in 0..width {
        b[pos + i] = le[i % 8];
    }
}

/// Edge values for a header number, relative to a file of `len` bytes.
fn edge_value(len: u64) -> impl Strategy<Value = u64> {
    prop_oneof![
        prop::sample::select(vec![
            0,
            1,
            2,
            3,
            4,
            11,
            12,
            len / 4,
            len / 4 + 1,
            len - 1,
            len,
            len + 1,
            (1 << 31) - 1,
            1 << 31,
            1 << 32,
            1 << 40,
            1 << 62,
            1 << 63,
            u64::MAX / 4,
            u64::MAX,
        ]),
        0u64..300,
        any::<u64>(),
    ]
}

/// Huge values for a declared dimension: every one makes the field larger
/// than the file.
fn huge_value(len: u64) -> impl Strategy<Value = u64> {
    prop_oneof![
        prop::sample::select(vec![
            len,
            len + 1,
            1 << 31,
            1 << 32,
            1 << 40,
            1 << 62,
            1 << 63,
            u64::MAX
        ]),
        len..=u64::MAX,
    ]
}

/// A grid dimension: mostly a usable one (2 to 4), sometimes 0 or 1.
fn dim() -> impl Strategy<Value = usize> {
    prop_oneof![6 => 2usize..5, 1 => 0usize..2]
}

fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// The fields an RGB `.bsdf` file has, with the element type of each.
const FIELDS: &[(&str, DType)] = &[
    ("description", DType::U8),
    ("phi_i", DType::F32),
    ("theta_i", DType::F32),
    ("sigma", DType::F32),
    ("ndf", DType::F32),
    ("vndf", DType::F32),
    ("luminance", DType::F32),
    ("rgb", DType::F32),
    ("jacobian", DType::U8),
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    /// Arbitrary bytes, bare or after the magic, the version and a field count.
    #[test]
    fn arbitrary_bytes(prefix in 0usize..4, count in any::<u32>(), tail in prop::collection::vec(any::<u8>(), 0..1024)) {
        let mut b = Vec::new();
        if prefix >= 1 {
            b.extend_from_slice(paperbsdf_io::rgl::tensor::MAGIC);
        }
        if prefix >= 2 {
            b.extend_from_slice(&[1, 0]);
        }
        if prefix >= 3 {
            b.extend_from_slice(&count.to_le_bytes());
        }
        b.extend_from_slice(&tail);
        let _ = check(b);
    }

    /// A real file cut at a random offset (most cuts in the header, where the
    /// reader has the most cases): always refused, saying why.
    #[test]
    fn truncated_real_file(which in any::<bool>(), in_header in any::<bool>(), at in any::<prop::sample::Index>()) {
        let full = real(which);
        let cut = if in_header { at.index(420) } else { at.index(full.len()) };
        let e = check(full[..cut].to_vec()).expect("a cut file was accepted");
        assert!(
            e.contains("truncated") || e.contains("not a tensor file") || e.contains("empty"),
            "cut {cut}: {e}"
        );
    }

    /// One to four header items of a real file set to edge values (field
    /// count, name length or bytes, rank, type code, data offset, a dimension).
    #[test]
    fn mutated_header(which in any::<bool>(),
                      edits in prop::collection::vec((any::<prop::sample::Index>(), edge_value(658_960)), 1..5)) {
        let (items, _) = real_layout(which);
        let mut b = real(which).to_vec();
        for (i, v) in &edits {
            let (_, pos, width) = items[i.index(items.len())];
            poke(&mut b, pos, width, *v);
        }
        let _ = check(b);
    }

    /// A dimension of a field declared so large that the field cannot be in the
    /// file is refused, naming the field, before anything of that size is
    /// allocated (the allocation limit of [`check`]).
    #[test]
    fn huge_declared_dimensions_are_refused(which in any::<bool>(), field in any::<prop::sample::Index>(),
                                            dim in any::<prop::sample::Index>(), v in huge_value(658_960)) {
        let (items, decls) = real_layout(which);
        let k = field.index(decls.len());
        let d = &decls[k];
        let j = dim.index(d.dims.len());
        let &(_, pos, width) = items.iter().find(|it| it.0 == Item::Dim(k, j)).unwrap();
        let mut b = real(which).to_vec();
        poke(&mut b, pos, width, v);
        let mut dims = d.dims.clone();
        dims[j] = v;
        let bytes = dims.iter().fold(d.size as u128, |a, &x| a.saturating_mul(x as u128));
        prop_assume!(dims.iter().all(|&x| x > 0) && d.offset as u128 + bytes > b.len() as u128);
        let e = check(b).expect("a field larger than the file was accepted");
        assert!(e.contains(&format!("field `{}`", d.name)), "{e}");
    }

    /// Bytes overwritten anywhere in a real file (data included: NaN and huge
    /// floats, non-increasing angle grids, a zero jacobian flag).
    #[test]
    fn corrupted_bytes(which in any::<bool>(),
                       edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let mut b = real(which).to_vec();
        let n = b.len();
        for (i, v) in &edits {
            b[i.index(n)] = *v;
        }
        let _ = check(b);
    }

    /// Small well-formed tensor files with the fields of an RGB file and
    /// consistent shapes (`np` incident azimuths, `nt` elevations, grids of 0
    /// to 3 points, arbitrary values, angle grids increasing or not), one field
    /// sometimes given an arbitrary shape (rank 0 to 5, dimensions 0 to 4), type
    /// or left out: the tensor layer accepts them, so this exercises the
    /// reader's shape checks, the warps' construction and evaluation.
    #[test]
    fn arbitrary_shapes(np in prop_oneof![4 => Just(1usize), 1 => 0usize..5], nt in prop_oneof![4 => 1usize..4, 1 => Just(0usize)],
                        vndf in (dim(), dim()), n in dim(), grid in (dim(), dim()),
                        start in -1.0f32..1.0, step in prop_oneof![4 => 0.01f32..1.0, 1 => Just(0.0f32), 1 => -1.0f32..0.0],
                        perturb in prop::option::weighted(0.3, (0usize..9, prop::collection::vec(0usize..5, 0..6), 0u8..5)),
                        values in prop::collection::vec(prop_oneof![6 => 0.0f32..2.0, 1 => Just(0.0f32), 1 => prop::num::f32::ANY], 1..64),
                        jacobian in any::<u8>()) {
        let shapes: Vec<Vec<usize>> = vec![
            vec![values.len() % 9],
            vec![np],
            vec![nt],
            vec![grid.0, grid.1],
            vec![grid.0, grid.1],
            vec![np, nt, vndf.0, vndf.1],
            vec![np, nt, n, n],
            vec![np, nt, 3, n, n],
            vec![1],
        ];
        let mut data = Vec::new();
        for (k, (shape, (name, dtype))) in shapes.into_iter().zip(FIELDS).enumerate() {
            let (mut shape, mut dtype, mut present) = (shape, *dtype, true);
            if let Some((f, s, code)) = &perturb {
                if *f == k {
                    match code {
                        0 => dtype = DType::I32,
                        1 => dtype = DType::F64,
                        2 => present = false,
                        _ => shape = s.clone(),
                    }
                }
            }
            let len: usize = shape.iter().product();
            let floats: Vec<f32> = if *name == "phi_i" || *name == "theta_i" {
                (0..len).map(|i| start + step * i as f32).collect()
            } else {
                (0..len).map(|i| values[i % values.len()]).collect()
            };
            let bytes = match dtype {
                DType::F32 => f32_bytes(&floats),
                DType::U8 if *name == "jacobian" => vec![jacobian; len],
                _ => (0..len * dtype.size()).map(|i| b"paper"[i % 5]).collect(),
            };
            if present {
                data.push((*name, dtype, shape, bytes));
            }
        }
        let fields: Vec<(&str, DType, &[usize], &[u8])> =
            data.iter().map(|(name, dtype, shape, bytes)| (*name, *dtype, &shape[..], &bytes[..])).collect();
        let _ = check(TensorFile::encode(&fields));
    }
}

/// The real files themselves are accepted (the properties above start from them).
#[test]
fn real_files_are_accepted() {
    for which in [true, false] {
        assert_eq!(check(real(which).to_vec()), None);
        let (items, decls) = real_layout(which);
        assert!(decls.iter().any(|d| d.name == "rgb" && d.dims.len() == 5));
        assert!(items.len() > 50);
    }
}
