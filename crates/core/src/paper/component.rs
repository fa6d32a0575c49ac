//! The components of the Paper BSDF (and of the comparison models): the
//! curves of the paper's plots, each available alone, and sets of them.

/// One component of a layered BSDF (the curves of the paper's plots).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Component {
    /// Reflection by the face the light arrives at (orange in the paper's plots).
    Surface,
    /// Single scattering in the medium (cyan).
    Single,
    /// Multiple scattering, the diffuse body (blue).
    Multiple,
    /// Light crossing the sheet unscattered.
    Direct,
}

impl Component {
    /// Every component, in a fixed order.
    pub const ALL: [Component; 4] = [
        Component::Surface,
        Component::Single,
        Component::Multiple,
        Component::Direct,
    ];

    /// Name used in files and on the command line (`surface`, `single`, `multiple`, `direct`).
    pub fn name(self) -> &'static str {
        match self {
            Component::Surface => "surface",
            Component::Single => "single",
            Component::Multiple => "multiple",
            Component::Direct => "direct",
        }
    }

    /// Parses a name of [`Component::name`] (case-insensitive).
    pub fn parse(s: &str) -> Option<Component> {
        Component::ALL.into_iter().find(|c| c.name().eq_ignore_ascii_case(s))
    }

    #[inline]
    fn bit(self) -> u8 {
        1 << (self as u8)
    }
}

impl std::fmt::Display for Component {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A set of [`Component`]s.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ComponentSet(pub u8);

impl ComponentSet {
    /// Every component.
    pub const ALL: ComponentSet = ComponentSet(0b1111);
    /// No component.
    pub const NONE: ComponentSet = ComponentSet(0);

    /// The set holding only `c`.
    pub fn only(c: Component) -> Self {
        ComponentSet(c.bit())
    }
    /// Whether `c` is in the set.
    #[inline]
    pub fn contains(self, c: Component) -> bool {
        self.0 & c.bit() != 0
    }
    /// The set with `c` added.
    pub fn with(self, c: Component) -> Self {
        ComponentSet(self.0 | c.bit())
    }
    /// The set with `c` removed.
    pub fn without(self, c: Component) -> Self {
        ComponentSet(self.0 & !c.bit())
    }
}

impl From<Component> for ComponentSet {
    fn from(c: Component) -> Self {
        ComponentSet::only(c)
    }
}
