//! The model file's shape, as serde reads it (with spans).

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct File {
    /// Absent: the model is named after its file.
    pub(super) model: Option<Spanned<Header>>,
    #[serde(default)]
    pub(super) parameters: IndexMap<Spanned<String>, Spanned<ParamDecl>>,
    pub(super) coordinates: Option<Spanned<Names>>,
    pub(super) velocities: Option<Spanned<Names>>,
    #[serde(default)]
    pub(super) definitions: IndexMap<Spanned<String>, Spanned<String>>,
    pub(super) dynamics: Option<Spanned<Dynamics>>,
    #[serde(default)]
    pub(super) body: Vec<Spanned<BodyDecl>>,
    pub(super) fields: Option<Spanned<Fields>>,
    #[serde(default)]
    pub(super) rolling: Vec<Spanned<RollingDecl>>,
    #[serde(default)]
    pub(super) knife_edge: Vec<Spanned<KnifeEdgeDecl>>,
    #[serde(default)]
    pub(super) spring: Vec<Spanned<SpringDecl>>,
    #[serde(default)]
    pub(super) wall: Vec<Spanned<WallDecl>>,
    #[serde(default)]
    pub(super) initial: IndexMap<Spanned<String>, Spanned<Number>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Header {
    /// Absent: the file's name without `.toml`.
    pub(super) name: Option<Spanned<String>>,
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

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct Dynamics {
    pub(super) kinetic_energy: Option<Spanned<String>>,
    pub(super) potential: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) holonomic: Vec<Spanned<String>>,
    #[serde(default)]
    pub(super) constraints: Vec<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WallDecl {
    /// Absent: `wall`, when it is the model's only wall
    /// ([`super::name_the_only_wall`] fills it in before anything reads
    /// it; [`WallDecl::name`]).
    pub(super) name: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) doc: String,
    pub(super) surface: Option<Spanned<String>>,
    pub(super) normal_velocity: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) contact: Vec<Spanned<String>>,
    /// With bodies: the body that meets the wall (absent with a shape:
    /// the model's only body).
    pub(super) body: Option<Spanned<String>>,
    /// With bodies: the wall's shape, one of these three.
    pub(super) plane: Option<Spanned<PlaneDecl>>,
    pub(super) sphere: Option<Spanned<RoundDecl>>,
    pub(super) cylinder: Option<Spanned<RoundDecl>>,
    /// With bodies: `smooth` (the default) or `rough`.
    pub(super) law: Option<Spanned<String>>,
}

impl WallDecl {
    /// Its name, given or the only wall's default.
    pub(super) fn name(&self) -> &Spanned<String> {
        self.name
            .as_ref()
            .expect("walls are named by `name_the_only_wall` before they are read")
    }
}

/// A rigid body (`[[body]]`): the bodies layer derives T, V and the
/// constraint and contact rows from these.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BodyDecl {
    pub(super) name: Spanned<String>,
    pub(super) mass: Spanned<Number>,
    /// A number (a ball), three principal moments, or a 3×3 tensor, in the
    /// body frame about the centre.
    pub(super) inertia: Option<Spanned<Inertia>>,
    /// The centre in the fixed frame, as expressions of the coordinates.
    pub(super) position: Spanned<Vec<Spanned<Number>>>,
    pub(super) orientation: Option<Spanned<OrientationDecl>>,
    /// The contact shape: a sphere of this radius about the centre (absent:
    /// the centre is a point that meets walls).
    pub(super) radius: Option<Spanned<Number>>,
    /// Or a disk (a coin's rim) about the centre.
    pub(super) disk: Option<Spanned<DiskDecl>>,
}

/// A disk's rim: its radius and its axis in the body frame (a unit vector).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DiskDecl {
    pub(super) radius: Spanned<Number>,
    pub(super) axis: Spanned<Vec<Spanned<Number>>>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(super) enum Inertia {
    Tensor(Vec<Vec<Number>>),
    Principal(Vec<Number>),
    Ball(Number),
}

/// One of: `angle` (with `axis`), `euler` with `angles`, `quaternion`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OrientationDecl {
    pub(super) angle: Option<Spanned<String>>,
    pub(super) axis: Option<Spanned<String>>,
    pub(super) euler: Option<Spanned<String>>,
    pub(super) angles: Option<Spanned<Vec<Spanned<String>>>>,
    pub(super) quaternion: Option<Spanned<Vec<Spanned<String>>>>,
}

/// Fields acting on every body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Fields {
    /// Uniform gravity, a vector (V = −Σ m g · position).
    pub(super) gravity: Option<Spanned<Vec<Spanned<Number>>>>,
}

/// The plane n · p = offset, free on the side n points to (n a unit vector).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PlaneDecl {
    pub(super) normal: Spanned<Vec<Spanned<Number>>>,
    #[serde(default)]
    pub(super) offset: Option<Spanned<Number>>,
}

/// A sphere (centre, radius) or a cylinder (centre, axis, radius), the body
/// inside it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RoundDecl {
    pub(super) centre: Spanned<Vec<Spanned<Number>>>,
    pub(super) axis: Option<Spanned<Vec<Spanned<Number>>>>,
    pub(super) radius: Spanned<Number>,
}

/// A ball rolling without slipping on a plane, or inside a sphere or a
/// cylinder (exactly one of the three).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RollingDecl {
    /// Absent: the model's only body.
    pub(super) body: Option<Spanned<String>>,
    pub(super) plane: Option<Spanned<PlaneDecl>>,
    pub(super) sphere: Option<Spanned<RoundDecl>>,
    pub(super) cylinder: Option<Spanned<RoundDecl>>,
}

/// A linear spring between two points: V = ½ k (|P₁ − P₂| − L)².
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SpringDecl {
    /// k > 0.
    pub(super) stiffness: Spanned<Number>,
    /// The rest length L ≥ 0 (0 if absent).
    pub(super) length: Option<Spanned<Number>>,
    /// The two ends.
    pub(super) ends: Spanned<Vec<Spanned<EndDecl>>>,
}

/// A spring's end: a point of a body (its centre, or `at` in the body
/// frame from the centre) or a point fixed in space.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EndDecl {
    pub(super) body: Option<Spanned<String>>,
    pub(super) at: Option<Spanned<Vec<Spanned<Number>>>>,
    pub(super) point: Option<Spanned<Vec<Spanned<Number>>>>,
}

/// A knife edge (skate) at the body's centre, its blade along a body-frame
/// direction, on a plane: the centre does not move across the blade.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct KnifeEdgeDecl {
    /// Absent: the model's only body.
    pub(super) body: Option<Spanned<String>>,
    pub(super) blade: Spanned<Vec<Spanned<Number>>>,
    pub(super) normal: Spanned<Vec<Spanned<Number>>>,
}
