//! The model file's shape, as serde reads it (with spans).

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct File {
    pub(super) model: Spanned<Header>,
    #[serde(default)]
    pub(super) parameters: IndexMap<Spanned<String>, Spanned<ParamDecl>>,
    pub(super) coordinates: Option<Spanned<Names>>,
    pub(super) velocities: Option<Spanned<Names>>,
    #[serde(default)]
    pub(super) definitions: IndexMap<Spanned<String>, Spanned<String>>,
    pub(super) dynamics: Spanned<Dynamics>,
    #[serde(default)]
    pub(super) wall: Vec<Spanned<WallDecl>>,
    #[serde(default)]
    pub(super) initial: IndexMap<Spanned<String>, Spanned<Number>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Header {
    pub(super) name: Spanned<String>,
    #[serde(default)]
    pub(super) doc: String,
    pub(super) projector: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(super) enum ParamDecl {
    Full {
        value: Option<Number>,
        #[serde(default)]
        doc: String,
    },
    Bare(Number),
}

#[derive(Debug, Deserialize, Clone)]
#[serde(untagged)]
pub(super) enum Number {
    Int(i64),
    Float(f64),
    Text(String),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Names {
    pub(super) names: Vec<Spanned<String>>,
    /// For coordinates: the names of their velocities (default `<name>_dot`).
    pub(super) velocities: Option<Vec<Spanned<String>>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Dynamics {
    pub(super) kinetic_energy: Spanned<String>,
    pub(super) potential: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) holonomic: Vec<Spanned<String>>,
    #[serde(default)]
    pub(super) constraints: Vec<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WallDecl {
    pub(super) name: Spanned<String>,
    #[serde(default)]
    pub(super) doc: String,
    pub(super) surface: Option<Spanned<String>>,
    pub(super) normal_velocity: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) contact: Vec<Spanned<String>>,
}
