//! The `tensor_file` container of Mitsuba and the RGL material database: a
//! 12-byte magic `tensor_file\0`, a two-byte version (1.0), a little-endian
//! `u32` field count, then per field its name (`u16` length and bytes), its
//! rank (`u16`), its element type (`u8`, Mitsuba 3's `Struct::Type` numbering:
//! 1 uint8, 2 int8, 3 uint16, 4 int16, 5 uint32, 6 int32, 7 uint64, 8 int64,
//! 9 float16, 10 float32, 11 float64; the RGL files use 1, 5 and 10), the byte offset of its data (`u64`) and
//! its shape (`rank` times `u64`). The layout is the one published with the
//! database (rgl.epfl.ch/materials, "file format") and read by Mitsuba's
//! `TensorFile`.
//!
//! Every size in the header is checked against the length of the file before
//! anything is allocated from it, so arbitrary bytes give an error, never a
//! panic or an unbounded allocation.

use std::collections::BTreeMap;

/// What is wrong with the bytes of a tensor file (the caller adds the file name).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct TensorError(pub String);

impl From<String> for TensorError {
    fn from(m: String) -> Self {
        TensorError(m)
    }
}

impl From<&str> for TensorError {
    fn from(m: &str) -> Self {
        TensorError(m.to_string())
    }
}

/// The magic bytes at the start of every tensor file.
pub const MAGIC: &[u8; 12] = b"tensor_file\0";

/// Element type of a field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DType {
    /// Signed 8-bit integer.
    I8,
    /// Unsigned 8-bit integer.
    U8,
    /// Signed 16-bit integer.
    I16,
    /// Unsigned 16-bit integer.
    U16,
    /// Signed 32-bit integer.
    I32,
    /// Unsigned 32-bit integer.
    U32,
    /// Signed 64-bit integer.
    I64,
    /// Unsigned 64-bit integer.
    U64,
    /// IEEE half precision.
    F16,
    /// IEEE single precision.
    F32,
    /// IEEE double precision.
    F64,
}

impl DType {
    /// The type's code in the file.
    pub fn code(self) -> u8 {
        match self {
            DType::I8 => 2,
            DType::U8 => 1,
            DType::I16 => 4,
            DType::U16 => 3,
            DType::I32 => 6,
            DType::U32 => 5,
            DType::I64 => 8,
            DType::U64 => 7,
            DType::F16 => 9,
            DType::F32 => 10,
            DType::F64 => 11,
        }
    }
    fn from_code(c: u8) -> Option<DType> {
        Some(match c {
            2 => DType::I8,
            1 => DType::U8,
            4 => DType::I16,
            3 => DType::U16,
            6 => DType::I32,
            5 => DType::U32,
            8 => DType::I64,
            7 => DType::U64,
            9 => DType::F16,
            10 => DType::F32,
            11 => DType::F64,
            _ => return None,
        })
    }
    /// Bytes per element.
    pub fn size(self) -> usize {
        match self {
            DType::I8 | DType::U8 => 1,
            DType::I16 | DType::U16 | DType::F16 => 2,
            DType::I32 | DType::U32 | DType::F32 => 4,
            DType::I64 | DType::U64 | DType::F64 => 8,
        }
    }
    /// The type's name as written in error messages.
    pub fn name(self) -> &'static str {
        match self {
            DType::I8 => "int8",
            DType::U8 => "uint8",
            DType::I16 => "int16",
            DType::U16 => "uint16",
            DType::I32 => "int32",
            DType::U32 => "uint32",
            DType::I64 => "int64",
            DType::U64 => "uint64",
            DType::F16 => "float16",
            DType::F32 => "float32",
            DType::F64 => "float64",
        }
    }
}

/// One field of a tensor file: its type, shape and the byte range of its data.
#[derive(Clone, Debug)]
pub struct Field {
    /// Element type.
    pub dtype: DType,
    /// Shape, outermost dimension first (row-major data).
    pub shape: Vec<usize>,
    /// Byte offset of the data in the file.
    pub offset: usize,
    /// Number of elements (product of the shape, checked to fit in the file).
    pub len: usize,
}

/// A parsed tensor file: the fields by name, and the file's bytes.
#[derive(Debug)]
pub struct TensorFile {
    /// Fields by name.
    pub fields: BTreeMap<String, Field>,
    bytes: Vec<u8>,
}

struct Cursor<'a> {
    b: &'a [u8],
    p: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8], TensorError> {
        let end = self.p.checked_add(n).filter(|&e| e <= self.b.len());
        match end {
            Some(e) => {
                let s = &self.b[self.p..e];
                self.p = e;
                Ok(s)
            }
            None => Err(TensorError(format!(
                "truncated header: {what} at byte {} needs {n} bytes, the file has {}",
                self.p,
                self.b.len()
            ))),
        }
    }
    fn u16(&mut self, what: &str) -> Result<u16, TensorError> {
        let s = self.take(2, what)?;
        Ok(u16::from_le_bytes([s[0], s[1]]))
    }
    fn u32(&mut self, what: &str) -> Result<u32, TensorError> {
        let s = self.take(4, what)?;
        Ok(u32::from_le_bytes(s.try_into().expect("4 bytes")))
    }
    fn u64(&mut self, what: &str) -> Result<u64, TensorError> {
        let s = self.take(8, what)?;
        Ok(u64::from_le_bytes(s.try_into().expect("8 bytes")))
    }
}

impl TensorFile {
    /// Parses the bytes of a tensor file. The error says what is wrong (the
    /// caller adds the file name).
    pub fn parse(bytes: Vec<u8>) -> Result<TensorFile, TensorError> {
        if bytes.is_empty() {
            return Err(TensorError::from("the file is empty (expected a tensor_file)"));
        }
        if bytes.len() < 18 || &bytes[..12] != MAGIC {
            if bytes.len() >= 12 && &bytes[..12] == MAGIC {
                return Err(TensorError::from(format!(
                    "truncated header: {} bytes, a tensor file header has at least 18",
                    bytes.len()
                )));
            }
            return Err(TensorError::from(
                "not a tensor file: it does not start with the magic bytes `tensor_file\\0` \
                 (RGL material files are `.bsdf` tensor files)",
            ));
        }
        let mut c = Cursor { b: &bytes, p: 12 };
        let ver = c.take(2, "version")?;
        if ver != [1, 0] {
            return Err(TensorError::from(format!(
                "unknown tensor file version {}.{} (only 1.0 is known)",
                ver[0], ver[1]
            )));
        }
        let n = c.u32("field count")? as usize;
        // Each field header has at least 2 + 2 + 1 + 8 bytes: a count the file cannot hold is refused before any allocation.
        if n > bytes.len() / 13 {
            return Err(TensorError::from(format!(
                "truncated or corrupt header: it declares {n} fields, more than a file of {} bytes can hold",
                bytes.len()
            )));
        }
        let mut fields = BTreeMap::new();
        for k in 0..n {
            let len = c.u16(&format!("name length of field {k}"))? as usize;
            let name_bytes = c.take(len, &format!("name of field {k}"))?;
            let name =
                String::from_utf8(name_bytes.to_vec()).map_err(|_| format!("the name of field {k} is not UTF-8"))?;
            let ndim = c.u16(&format!("rank of field `{name}`"))? as usize;
            let code = c.take(1, &format!("type of field `{name}`"))?[0];
            let dtype = DType::from_code(code)
                .ok_or_else(|| format!("field `{name}` has an unknown element type code {code}"))?;
            let offset = c.u64(&format!("offset of field `{name}`"))?;
            // the shape bytes must be present before the vector is allocated
            if ndim.checked_mul(8).is_none_or(|s| c.p + s > bytes.len()) {
                return Err(TensorError::from(format!(
                    "truncated header: the shape of field `{name}` (rank {ndim}) runs past the end of the file"
                )));
            }
            let mut shape = Vec::with_capacity(ndim);
            let mut count: u64 = 1;
            for _ in 0..ndim {
                let s = c.u64(&format!("shape of field `{name}`"))?;
                count = count
                    .checked_mul(s)
                    .ok_or_else(|| format!("field `{name}`: shape overflows"))?;
                shape.push(s as usize);
            }
            let nbytes = count
                .checked_mul(dtype.size() as u64)
                .ok_or_else(|| format!("field `{name}`: size overflows"))?;
            let end = offset.checked_add(nbytes);
            if end.is_none_or(|e| e > bytes.len() as u64) {
                return Err(TensorError::from(format!(
                    "truncated file: field `{name}` ({} x {:?}) needs bytes {offset}..{} but the file has {} bytes",
                    dtype.name(),
                    shape,
                    offset as u128 + nbytes as u128,
                    bytes.len()
                )));
            }
            if fields
                .insert(
                    name.clone(),
                    Field {
                        dtype,
                        shape,
                        offset: offset as usize,
                        len: count as usize,
                    },
                )
                .is_some()
            {
                return Err(TensorError::from(format!("field `{name}` appears twice")));
            }
        }
        Ok(TensorFile { fields, bytes })
    }

    /// Encodes fields `(name, type, shape, data bytes)` as a tensor file (data
    /// aligned to 8 bytes, as Mitsuba writes them). For tests and tools.
    pub fn encode(fields: &[(&str, DType, &[usize], &[u8])]) -> Vec<u8> {
        let mut head = Vec::new();
        head.extend_from_slice(MAGIC);
        head.extend_from_slice(&[1, 0]);
        head.extend_from_slice(&(fields.len() as u32).to_le_bytes());
        let header_len = head.len()
            + fields
                .iter()
                .map(|(n, _, s, _)| 2 + n.len() + 2 + 1 + 8 + 8 * s.len())
                .sum::<usize>();
        let mut offset = header_len.div_ceil(8) * 8;
        let mut body = Vec::new();
        for (name, dtype, shape, data) in fields {
            head.extend_from_slice(&(name.len() as u16).to_le_bytes());
            head.extend_from_slice(name.as_bytes());
            head.extend_from_slice(&(shape.len() as u16).to_le_bytes());
            head.push(dtype.code());
            head.extend_from_slice(&(offset as u64).to_le_bytes());
            for s in shape.iter() {
                head.extend_from_slice(&(*s as u64).to_le_bytes());
            }
            body.push((offset, *data));
            offset = (offset + data.len()).div_ceil(8) * 8;
        }
        let mut out = head;
        for (off, data) in body {
            out.resize(off, 0);
            out.extend_from_slice(data);
        }
        out
    }

    /// The field `name`, or an error naming it.
    pub fn field(&self, name: &str) -> Result<&Field, TensorError> {
        self.fields.get(name).ok_or_else(|| {
            TensorError(format!(
                "missing field `{name}` (fields present: {})",
                self.fields.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })
    }

    /// The raw bytes of a field.
    pub fn bytes(&self, f: &Field) -> &[u8] {
        &self.bytes[f.offset..f.offset + f.len * f.dtype.size()]
    }

    /// The elements of a float32 field, as f32.
    pub fn f32s(&self, name: &str) -> Result<Vec<f32>, TensorError> {
        let f = self.field(name)?;
        if f.dtype != DType::F32 {
            return Err(TensorError::from(format!(
                "field `{name}` has type {}, expected float32",
                f.dtype.name()
            )));
        }
        Ok(self
            .bytes(f)
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }
}
