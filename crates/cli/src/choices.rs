//! The enumerated values of the command line's flags, as clap value parsers, so
//! that clap refuses a bad value naming the flag and the allowed values
//! (`error: invalid value 'foo' for '--component <COMPONENT>'`, then
//! `[possible values: surface, single, multiple, direct, all]`) and lists them
//! in `--help`. The names are those of the crate that defines each thing
//! (`Component::name`, `Distribution::name`, `FaceScattering::name` of
//! paperbsdf-core); choices that exist only on the command line are enums
//! deriving `clap::ValueEnum` next to their command.

use clap::builder::{PossibleValuesParser, TypedValueParser};
use paperbsdf_core::paper::Component;
use paperbsdf_core::{Distribution, FaceScattering};

/// `--component`: one component of a model, or `all` of them (`None`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ComponentChoice(pub Option<Component>);

/// The parser of `--component`: a [`Component::name`] or `all` (any case).
pub fn component() -> impl TypedValueParser<Value = ComponentChoice> {
    PossibleValuesParser::new(Component::ALL.map(Component::name).into_iter().chain(["all"]))
        .map(|s| ComponentChoice(Component::parse(&s)))
}

/// The microfacet distributions, in the order `--help` lists them.
const DISTRIBUTIONS: [Distribution; 2] = [Distribution::Ggx, Distribution::Beckmann];

/// The parser of a microfacet distribution's name ([`Distribution::name`], any case).
pub fn distribution() -> impl TypedValueParser<Value = Distribution> {
    PossibleValuesParser::new(DISTRIBUTIONS.map(Distribution::name))
        .map(|s| Distribution::parse(&s).expect("clap passes only the possible values"))
}

/// The faces' scattering, in the order `--help` lists them.
const FACE_SCATTERINGS: [FaceScattering; 2] = [FaceScattering::Multiple, FaceScattering::Single];

/// The parser of `--face-scattering` ([`FaceScattering::name`], any case).
pub fn face_scattering() -> impl TypedValueParser<Value = FaceScattering> {
    PossibleValuesParser::new(FACE_SCATTERINGS.map(FaceScattering::name)).map(|s| {
        s.parse::<FaceScattering>()
            .expect("clap passes only the possible values")
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Args {
        #[arg(long, default_value = "all", value_parser = component(), ignore_case = true)]
        component: ComponentChoice,
        #[arg(long, value_delimiter = ',', default_value = "ggx,beckmann", value_parser = distribution(), ignore_case = true)]
        dists: Vec<Distribution>,
        #[arg(long, default_value = "multiple", value_parser = face_scattering(), ignore_case = true)]
        face_scattering: FaceScattering,
    }

    /// Every name of the core crate parses to its value; others are clap's
    /// error, naming the flag and the possible values.
    #[test]
    fn names_of_the_core_crate() {
        let a = Args::try_parse_from(["x"]).unwrap();
        assert_eq!(a.component, ComponentChoice(None));
        assert_eq!(a.dists, DISTRIBUTIONS);
        assert_eq!(a.face_scattering, FaceScattering::Multiple);
        for c in Component::ALL {
            let a = Args::try_parse_from(["x", "--component", c.name()]).unwrap();
            assert_eq!(a.component, ComponentChoice(Some(c)));
        }
        let a = Args::try_parse_from([
            "x",
            "--component",
            "Surface",
            "--dists",
            "BECKMANN",
            "--face-scattering",
            "single",
        ])
        .unwrap();
        assert_eq!(a.component, ComponentChoice(Some(Component::Surface)));
        assert_eq!(a.dists, [Distribution::Beckmann]);
        assert_eq!(a.face_scattering, FaceScattering::Single);
        let e = Args::try_parse_from(["x", "--component", "foo"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("invalid value 'foo' for '--component <COMPONENT>'")
                && e.contains("[possible values: surface, single, multiple, direct, all]"),
            "{e}"
        );
        let e = Args::try_parse_from(["x", "--dists", "ggx,gauss"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("'gauss'") && e.contains("[possible values: ggx, beckmann]"),
            "{e}"
        );
        let e = Args::try_parse_from(["x", "--face-scattering", "double"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("[possible values: multiple, single]"), "{e}");
    }
}
