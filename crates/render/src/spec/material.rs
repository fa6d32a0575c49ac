//! `[materials.NAME]`: one variant of [`MaterialSpec`] per material `type`,
//! each a struct with exactly the keys of that type.
//!
//! The table is read by hand rather than by serde's internally tagged enums,
//! which buffer the whole table and so lose the place of each key in the file.
//! Here `type` is read first (TOML tables come in the file's order; keys
//! written before `type` are held back and replayed) and the variant's derived
//! deserializer reads the rest of the table itself, so an unknown key or a
//! wrong value is reported at its line. A key of another material type is
//! refused with the keys that do apply.

use super::schema::{ColourSpec, InkMapSpec, ThicknessMapSpec};
use paperbsdf_core::{Colour, Distribution, FaceScattering};
use serde::de::value::{MapAccessDeserializer, StrDeserializer};
use serde::de::{DeserializeOwned, DeserializeSeed, Deserializer, Error as _, MapAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// `[materials.NAME]`: a material, by its `type`.
#[derive(Debug)]
pub enum MaterialSpec {
    /// `type = "diffuse"`.
    Diffuse(DiffuseSpec),
    /// `type = "dielectric"`.
    Dielectric(DielectricSpec),
    /// `type = "paper"`.
    Paper(Box<PaperSpec>),
    /// `type = "measured"`.
    Measured(MeasuredSpec),
    /// `type = "black"`: no keys.
    Black,
}

/// `type = "diffuse"`: Lambertian reflection.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct DiffuseSpec {
    /// Reflectance in [0, 1] (a number, RGB or a texture); required.
    pub reflectance: Option<ColourSpec>,
}

/// `type = "dielectric"`: a rough dielectric interface.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct DielectricSpec {
    /// Relative index of refraction (inside over outside), [1, 5]; required.
    pub eta: Option<f64>,
    /// Roughness alpha, [0, pi/2]; 0 (the default) is smooth.
    pub m: Option<f64>,
    /// `ggx` (default) or `beckmann`.
    pub dist: Option<Distribution>,
}

/// `type = "paper"`: the Paper BSDF's parameters, from a preset or a parameter
/// file, each overridable by a key of the same name (those of
/// [`paperbsdf_core::PaperParams`]), and optional thickness and ink maps.
///
/// Only the parameters are serialised (`None` ones left out), giving the table
/// of the keys set here that is laid over the preset's or file's.
#[derive(Deserialize, Serialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct PaperSpec {
    /// A preset name.
    #[serde(skip_serializing)]
    pub preset: Option<String>,
    /// A parameter file (JSON or TOML, the format of `paperbsdf eval --params`), relative to the scene file.
    #[serde(skip_serializing)]
    pub params: Option<String>,
    /// Thickness, mm.
    pub d: Option<f64>,
    /// Absorption, 1/mm.
    pub sigma_a: Option<Colour>,
    /// Scattering, 1/mm.
    pub sigma_s: Option<Colour>,
    /// Forward HG lobe mean cosine.
    pub g_f: Option<f64>,
    /// Backward HG lobe mean cosine.
    pub g_b: Option<f64>,
    /// Backward lobe weight.
    pub w_b: Option<f64>,
    /// Front face index.
    pub eta_f: Option<f64>,
    /// Back face index.
    pub eta_b: Option<f64>,
    /// Front face roughness.
    pub m_f: Option<f64>,
    /// Back face roughness.
    pub m_b: Option<f64>,
    /// Front face distribution.
    pub dist_f: Option<Distribution>,
    /// Back face distribution.
    pub dist_b: Option<Distribution>,
    /// The faces' microfacet scattering, `"multiple"` (default) or `"single"`.
    pub face_scattering: Option<FaceScattering>,
    /// Thickness map.
    #[serde(skip_serializing)]
    pub thickness_map: Option<ThicknessMapSpec>,
    /// Ink map.
    #[serde(skip_serializing)]
    pub ink_map: Option<InkMapSpec>,
    /// The model that renders the sheet: `"paper"` (default) or `"slab"`.
    #[serde(skip_serializing)]
    pub model: Option<SheetModel>,
    /// With `model = "slab"`: the nodes per hemisphere of its
    /// discretisation, 2 to 256 (default 32; `paperbsdf eval --slab-nodes`).
    #[serde(skip_serializing)]
    pub slab_nodes: Option<usize>,
}

/// The model of a `type = "paper"` material (docs/design.md 4.7).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum SheetModel {
    /// The Paper BSDF (`paperbsdf_core::PaperBsdf`): closed forms, built in
    /// about 0.1 ms.
    #[default]
    Paper,
    /// The same sheet solved by adding-doubling (`paperbsdf_slab::SlabBsdf`):
    /// accurate for thin and weakly scattering sheets too, built in about
    /// 0.5 to 1 s per parameter set (each level of a thickness or ink map is
    /// one).
    Slab,
}

/// `type = "measured"`: a measured RGL BRDF.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct MeasuredSpec {
    /// An RGL `.bsdf` file (RGB variant), relative to the scene file; required.
    pub file: Option<String>,
}

/// `type = "black"` has no keys.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BlackSpec {}

/// The material types, as written in `type`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialType {
    /// `diffuse`.
    Diffuse,
    /// `dielectric`.
    Dielectric,
    /// `paper`.
    Paper,
    /// `measured`.
    Measured,
    /// `black`.
    Black,
}

impl MaterialType {
    /// Every type, in the order of the documentation.
    pub const ALL: [MaterialType; 5] = [
        MaterialType::Diffuse,
        MaterialType::Dielectric,
        MaterialType::Paper,
        MaterialType::Measured,
        MaterialType::Black,
    ];

    /// The name written in `type`.
    pub fn name(self) -> &'static str {
        match self {
            MaterialType::Diffuse => "diffuse",
            MaterialType::Dielectric => "dielectric",
            MaterialType::Paper => "paper",
            MaterialType::Measured => "measured",
            MaterialType::Black => "black",
        }
    }

    /// The keys of a table of this type besides `type`, in their struct's order.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            MaterialType::Diffuse => keys_of::<DiffuseSpec>(),
            MaterialType::Dielectric => keys_of::<DielectricSpec>(),
            MaterialType::Paper => keys_of::<PaperSpec>(),
            MaterialType::Measured => keys_of::<MeasuredSpec>(),
            MaterialType::Black => keys_of::<BlackSpec>(),
        }
    }

    /// `type` and the keys of every type, each once.
    fn all_keys() -> &'static [&'static str] {
        static ALL: OnceLock<Vec<&'static str>> = OnceLock::new();
        ALL.get_or_init(|| {
            let mut all = vec!["type"];
            for k in MaterialType::ALL.iter().flat_map(|t| t.keys()) {
                if !all.contains(k) {
                    all.push(k);
                }
            }
            all
        })
    }
}

impl std::fmt::Display for MaterialType {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl<'de> Deserialize<'de> for MaterialType {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        MaterialType::ALL.into_iter().find(|t| t.name() == name).ok_or_else(|| {
            let names: Vec<_> = MaterialType::ALL.iter().map(|t| t.name()).collect();
            D::Error::custom(format!(
                "unknown material type `{name}` (allowed: {})",
                names.join(", ")
            ))
        })
    }
}

/// The keys of the table `T` reads: the field names serde's derive passes to
/// `deserialize_struct` (so each key is written once, in its struct).
pub(super) fn keys_of<T: DeserializeOwned>() -> &'static [&'static str] {
    struct Probe<'a>(&'a mut &'static [&'static str]);
    impl<'de> Deserializer<'de> for Probe<'_> {
        type Error = serde::de::value::Error;
        fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Self::Error> {
            Err(Self::Error::custom("not a struct"))
        }
        fn deserialize_struct<V: Visitor<'de>>(
            self,
            _: &'static str,
            fields: &'static [&'static str],
            _: V,
        ) -> Result<V::Value, Self::Error> {
            *self.0 = fields;
            Err(Self::Error::custom("probed"))
        }
        serde::forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
            option unit unit_struct newtype_struct seq tuple tuple_struct map enum identifier ignored_any
        }
    }
    let mut fields: &'static [&'static str] = &[];
    let _ = T::deserialize(Probe(&mut fields));
    fields
}

impl<'de> Deserialize<'de> for MaterialSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(TableVisitor)
    }
}

struct TableVisitor;

impl<'de> Visitor<'de> for TableVisitor {
    type Value = MaterialSpec;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a material table with a `type`")
    }

    fn visit_map<M: MapAccess<'de>>(self, mut map: M) -> Result<MaterialSpec, M::Error> {
        let mut ahead = vec![];
        let kind = loop {
            match map.next_key_seed(AnyMaterialKey)? {
                Some(k) if k == "type" => break map.next_value::<MaterialType>()?,
                Some(k) => {
                    let v: toml::Value = map.next_value()?;
                    ahead.push((k, v));
                }
                None => return Err(M::Error::missing_field("type")),
            }
        };
        let rest = MapAccessDeserializer::new(Rest {
            kind,
            ahead: ahead.into_iter(),
            value: None,
            map,
        });
        Ok(match kind {
            MaterialType::Diffuse => MaterialSpec::Diffuse(DiffuseSpec::deserialize(rest)?),
            MaterialType::Dielectric => MaterialSpec::Dielectric(DielectricSpec::deserialize(rest)?),
            MaterialType::Paper => MaterialSpec::Paper(Box::new(PaperSpec::deserialize(rest)?)),
            MaterialType::Measured => MaterialSpec::Measured(MeasuredSpec::deserialize(rest)?),
            MaterialType::Black => {
                BlackSpec::deserialize(rest)?;
                MaterialSpec::Black
            }
        })
    }
}

/// A key written before `type`: `type` or a key of some material type.
struct AnyMaterialKey;

impl<'de> DeserializeSeed<'de> for AnyMaterialKey {
    type Value = String;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<String, D::Error> {
        let key = String::deserialize(d)?;
        let all = MaterialType::all_keys();
        if all.contains(&key.as_str()) {
            Ok(key)
        } else {
            Err(D::Error::unknown_field(&key, all))
        }
    }
}

/// The table after its `type`: the keys held back before it, then the rest.
struct Rest<M> {
    /// The material's type.
    kind: MaterialType,
    /// Keys (and values) read before `type`.
    ahead: std::vec::IntoIter<(String, toml::Value)>,
    /// The value of the held-back key just replayed.
    value: Option<(String, toml::Value)>,
    /// The rest of the table.
    map: M,
}

impl<'de, M: MapAccess<'de>> MapAccess<'de> for Rest<M> {
    type Error = M::Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>, M::Error> {
        let seed = OwnKey { kind: self.kind, seed };
        match self.ahead.next() {
            Some((k, v)) => {
                let key = seed.deserialize(StrDeserializer::<M::Error>::new(&k))?;
                self.value = Some((k, v));
                Ok(Some(key))
            }
            None => self.map.next_key_seed(seed),
        }
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, M::Error> {
        match self.value.take() {
            // Its place in the file is lost: the message names the key.
            Some((k, v)) => seed
                .deserialize(v)
                .map_err(|e| M::Error::custom(format!("`{k}`: {}", e.message()))),
            None => self.map.next_value_seed(seed),
        }
    }
}

/// A key of a table of type `kind`: a key of another type is refused with the
/// keys that apply; others go to the variant's own key seed (which refuses
/// unknown keys with the keys it expects).
struct OwnKey<K> {
    kind: MaterialType,
    seed: K,
}

impl<'de, K: DeserializeSeed<'de>> DeserializeSeed<'de> for OwnKey<K> {
    type Value = K::Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<K::Value, D::Error> {
        let key = String::deserialize(d)?;
        let own = self.kind.keys();
        if !own.contains(&key.as_str()) && MaterialType::all_keys().contains(&key.as_str()) {
            return Err(D::Error::custom(format!(
                "key `{key}` does not apply to a `{}` material (allowed: {})",
                self.kind,
                own.join(", ")
            )));
        }
        self.seed.deserialize(StrDeserializer::<D::Error>::new(&key))
    }
}
