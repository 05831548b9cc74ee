//! Scenes for the transition harness: objects with a fine and a coarse LOD, a camera that stands
//! still or moves, built in code or read from RON.
//!
//! ```ron
//! (
//!     name: "two-spheres",
//!     camera: (eye: (0.0, 1.0, 6.0), target: (0.0, 0.0, 0.0), moving_eye: (1.5, 1.2, 5.0)),
//!     objects: [
//!         (fine: Sphere(rings: 24, segments: 48), coarse: Cube,
//!          fine_color: (0.9, 0.2, 0.1), coarse_color: (0.1, 0.3, 0.9), position: (0.0, 0.0, 0.0)),
//!         (fine: Cube, coarse: Cube, fine_color: (0.8, 0.8, 0.7), coarse_color: (0.8, 0.8, 0.7),
//!          position: (0.0, 0.0, -3.0), scale: (4.0, 3.0, 0.2), transition: false),
//!     ],
//! )
//! ```

use std::path::Path;

use glam::{Mat4, Vec2, Vec3, Vec4};
use serde::{Deserialize, Serialize};

use lodkit_scenes::mesh::Mesh;

/// The most objects a scene may have (each transition draws two items per object).
pub const MAX_OBJECTS: usize = 100;

/// The most triangles a scene may have, counting both LODs of every object.
pub const MAX_TRIANGLES: u64 = 4_000_000;

/// A scene of the transition harness.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoScene {
    /// Name used in file names and tables (letters, digits, `-`, `_`).
    pub name: String,
    /// Camera.
    pub camera: DemoCamera,
    /// Objects; those with `transition: true` go from their fine to their coarse LOD.
    pub objects: Vec<DemoObject>,
}

/// Camera of a scene; the moving camera goes from `eye` to `moving_eye` over the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoCamera {
    /// Eye position of the static camera and start of the moving one.
    pub eye: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Where the moving camera ends.
    pub moving_eye: [f32; 3],
    /// Vertical field of view in radians (default 0.8).
    #[serde(default = "default_fov")]
    pub fov_y: f32,
}

fn default_fov() -> f32 {
    0.8
}

fn unit_scale() -> [f32; 3] {
    [1.0; 3]
}

fn yes() -> bool {
    true
}

/// One object with two LODs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoObject {
    /// Shape of the fine LOD (LOD 0).
    pub fine: Shape,
    /// Shape of the coarse LOD (LOD 1).
    pub coarse: Shape,
    /// Linear RGB of the fine LOD.
    pub fine_color: [f32; 3],
    /// Linear RGB of the coarse LOD.
    pub coarse_color: [f32; 3],
    /// World position.
    pub position: [f32; 3],
    /// Scale per axis (default 1).
    #[serde(default = "unit_scale")]
    pub scale: [f32; 3],
    /// Whether it transitions during the run (default true); `false` makes it scenery drawn at
    /// its fine LOD.
    #[serde(default = "yes")]
    pub transition: bool,
    /// Wind sway of both LODs in the vertex stage: amplitude in object units at the top of a
    /// unit-high mesh (default 0, at most 1), animated every frame.
    #[serde(default)]
    pub sway: f32,
}

/// A procedural shape.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// UV sphere of radius 1 (rings 2..=256, segments 3..=512).
    Sphere {
        /// Rings from pole to pole.
        rings: u32,
        /// Segments around.
        segments: u32,
    },
    /// Cube from -1 to 1.
    Cube,
    /// Box from -half to half (each half-size in (0, 100]).
    Box {
        /// Half-sizes along x, y, z.
        half: [f32; 3],
    },
    /// Tree-like cluster: a trunk and `puffs` spheres of `rings` rings (puffs 1..=32).
    Tree {
        /// Canopy spheres.
        puffs: u32,
        /// Rings of each canopy sphere (segments are twice as many).
        rings: u32,
    },
    /// Alpha-tested billboard impostor of `Tree { puffs, rings }`: a card over the tree's front
    /// (x, y) extent, facing +z, whose alpha mask is the tree's silhouette, rendered when the
    /// scene is loaded. One impostor kind per scene (the renderers bind one mask).
    Impostor {
        /// Canopy spheres of the tree it stands for.
        puffs: u32,
        /// Rings of each canopy sphere of that tree.
        rings: u32,
    },
    /// Level `level` of the demo's generated LOD chain ([`super::chain`]), 0 the original.
    Chain {
        /// The level.
        level: u32,
    },
}

impl Shape {
    /// The mesh of the shape.
    pub fn mesh(self) -> Mesh {
        match self {
            Shape::Impostor { .. } => {
                let (min, max) = self.card_rect();
                Mesh::card(min, max)
            }
            Shape::Sphere { rings, segments } => Mesh::sphere(rings, segments),
            Shape::Cube => Mesh::cube(),
            Shape::Chain { level } => super::chain_levels::level_mesh(level).unwrap_or_default(),
            Shape::Box { half } => {
                let mut m = Mesh::default();
                m.append(&Mesh::cube(), Mat4::from_scale(Vec3::from(half)));
                m
            }
            Shape::Tree { puffs, rings } => {
                let mut m = Mesh::default();
                let trunk = Mat4::from_translation(Vec3::new(0.0, -0.6, 0.0))
                    * Mat4::from_scale(Vec3::new(0.12, 0.4, 0.12));
                m.append(&Mesh::cube(), trunk);
                let puff = Mesh::sphere(rings, rings * 2);
                for k in 0..puffs {
                    // Puffs on a golden-angle spiral around the canopy's center.
                    let a = k as f32 * 2.399_963;
                    let h = if puffs == 1 {
                        0.0
                    } else {
                        k as f32 / (puffs - 1) as f32 - 0.5
                    };
                    let rad = if puffs == 1 { 0.0 } else { 0.35 };
                    let c = Vec3::new(rad * a.cos(), 0.2 + 0.5 * h, rad * a.sin());
                    let size = if puffs == 1 { 0.6 } else { 0.38 };
                    m.append(
                        &puff,
                        Mat4::from_translation(c) * Mat4::from_scale(Vec3::splat(size)),
                    );
                }
                m
            }
        }
    }

    /// Triangles of the shape's mesh, without building it.
    pub fn triangles(self) -> u64 {
        let sphere = |rings: u32, segments: u32| 2 * u64::from(rings) * u64::from(segments);
        match self {
            Shape::Sphere { rings, segments } => sphere(rings.max(2), segments.max(3)),
            Shape::Cube | Shape::Box { .. } => 12,
            Shape::Impostor { .. } => 2,
            Shape::Chain { .. } => self.mesh().triangles() as u64,
            Shape::Tree { puffs, rings } => {
                12 + u64::from(puffs) * sphere(rings.max(2), rings.saturating_mul(2).max(3))
            }
        }
    }

    /// The tree an impostor stands for.
    pub fn impostor_of(self) -> Option<Shape> {
        match self {
            Shape::Impostor { puffs, rings } => Some(Shape::Tree { puffs, rings }),
            _ => None,
        }
    }

    /// The object-space rectangle (x, y) an impostor's card and mask cover: its tree's extent.
    pub fn card_rect(self) -> (Vec2, Vec2) {
        let tree = self.impostor_of().unwrap_or(self).mesh();
        let (min, max) = tree.bounds().unwrap_or((Vec3::NEG_ONE, Vec3::ONE));
        (min.truncate(), max.truncate())
    }

    /// Where the alpha mask lies on the shape (`lodkit::alpha_mask`): an impostor's card
    /// rectangle; zero (no alpha test) for the others.
    pub fn alpha_rect(self) -> Vec4 {
        match self {
            Shape::Impostor { .. } => {
                let (min, max) = self.card_rect();
                lodkit::alpha_mask::alpha_mask_rect(min, max)
            }
            _ => Vec4::ZERO,
        }
    }

    fn check(self) -> Result<(), String> {
        match self {
            Shape::Sphere { rings, segments } if !(2..=256).contains(&rings) => Err(format!(
                "Sphere rings = {rings} is outside 2..=256 (segments = {segments})"
            )),
            Shape::Sphere { segments, .. } if !(3..=512).contains(&segments) => {
                Err(format!("Sphere segments = {segments} is outside 3..=512"))
            }
            Shape::Tree { puffs, .. } | Shape::Impostor { puffs, .. }
                if !(1..=32).contains(&puffs) =>
            {
                Err(format!("puffs = {puffs} is outside 1..=32"))
            }
            Shape::Tree { rings, .. } | Shape::Impostor { rings, .. }
                if !(2..=64).contains(&rings) =>
            {
                Err(format!("rings = {rings} is outside 2..=64"))
            }
            Shape::Chain { level } if level as usize >= super::chain_levels::levels() => {
                Err(format!(
                    "Chain level = {level}: the chain has {} levels",
                    super::chain_levels::levels()
                ))
            }
            Shape::Box { half } if !half.iter().all(|h| *h > 0.0 && *h <= 100.0) => {
                Err(format!("Box half = {half:?} must lie in (0, 100]"))
            }
            _ => Ok(()),
        }
    }
}

/// A scene file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// RON syntax or a field of the wrong type.
    #[error("{path}:{line}:{column}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// Values that parse but cannot be rendered.
    #[error("{path}: {message}")]
    Invalid {
        /// The file (or `built-in`).
        path: String,
        /// What is wrong and where (`objects[3].scale`, ...).
        message: String,
    },
}

impl DemoScene {
    /// Reads and checks a RON scene file.
    pub fn from_file(path: &Path) -> Result<Self, SceneError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            path: shown.clone(),
            source,
        })?;
        Self::from_ron(&text, &shown)
    }

    /// Parses and checks a RON scene; `path` names it in errors.
    pub fn from_ron(text: &str, path: &str) -> Result<Self, SceneError> {
        let scene: DemoScene = ron::from_str(text).map_err(|e| SceneError::Parse {
            path: path.to_owned(),
            line: e.span.start.line,
            column: e.span.start.col,
            message: e.code.to_string(),
        })?;
        scene.check().map_err(|message| SceneError::Invalid {
            path: path.to_owned(),
            message,
        })?;
        Ok(scene)
    }

    /// Checks names, counts and values; the message names the field.
    pub fn check(&self) -> Result<(), String> {
        let name_ok = !self.name.is_empty()
            && self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
        if !name_ok {
            return Err(format!(
                "name `{}` must be non-empty letters, digits, `-` or `_`",
                self.name
            ));
        }
        if self.objects.len() > MAX_OBJECTS {
            return Err(format!(
                "objects: {} objects, at most {MAX_OBJECTS}",
                self.objects.len()
            ));
        }
        if !self.objects.iter().any(|o| o.transition) {
            return Err("objects: no object has `transition: true`".to_owned());
        }
        let c = &self.camera;
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if !finite(&c.eye) || !finite(&c.target) || !finite(&c.moving_eye) {
            return Err("camera: eye, target and moving_eye must be finite".to_owned());
        }
        let target = Vec3::from(c.target);
        for (field, eye) in [("eye", c.eye), ("moving_eye", c.moving_eye)] {
            let dir = target - Vec3::from(eye);
            if dir.length() < 1e-3 || dir.normalize().cross(Vec3::Y).length() < 1e-3 {
                return Err(format!(
                    "camera.{field} = {eye:?} looks straight up or down at the target (or sits \
                     on it): the camera's up axis is +Y"
                ));
            }
        }
        // The moving camera goes along the segment from eye to moving_eye.
        let (a, b) = (Vec3::from(c.eye), Vec3::from(c.moving_eye));
        let s = ((target - a).dot(b - a) / (b - a).length_squared().max(1e-12)).clamp(0.0, 1.0);
        let closest = a.lerp(b, s);
        let dir = target - closest;
        if dir.length() < 1e-3 || dir.normalize().cross(Vec3::Y).length() < 1e-3 {
            return Err(format!(
                "camera: the path from eye to moving_eye passes through the target or straight \
                 above or below it (at {:?})",
                closest.to_array()
            ));
        }
        if !(c.fov_y > 0.01 && c.fov_y < 3.1) {
            return Err(format!("camera.fov_y = {} is outside (0.01, 3.1)", c.fov_y));
        }
        let mut triangles = 0u64;
        for (i, o) in self.objects.iter().enumerate() {
            let at = |m: String| format!("objects[{i}].{m}");
            o.fine.check().map_err(|m| at(format!("fine: {m}")))?;
            o.coarse.check().map_err(|m| at(format!("coarse: {m}")))?;
            if !finite(&o.position) {
                return Err(at(format!("position = {:?} is not finite", o.position)));
            }
            if !o.scale.iter().all(|s| s.is_finite() && *s > 0.0) {
                return Err(at(format!("scale = {:?} must be > 0", o.scale)));
            }
            if !(0.0..=1.0).contains(&o.sway) {
                return Err(at(format!("sway = {} is outside 0..=1", o.sway)));
            }
            triangles += o.fine.triangles() + o.coarse.triangles();
            for (field, rgb) in [
                ("fine_color", o.fine_color),
                ("coarse_color", o.coarse_color),
            ] {
                if !rgb.iter().all(|v| (0.0..=1.0).contains(v)) {
                    return Err(at(format!("{field} = {rgb:?} is outside 0..=1")));
                }
            }
        }
        let mut impostors: Vec<Shape> = Vec::new();
        for shape in self.objects.iter().flat_map(|o| [o.fine, o.coarse]) {
            if shape.impostor_of().is_some() && !impostors.contains(&shape) {
                impostors.push(shape);
            }
        }
        if impostors.len() > 1 {
            return Err(format!(
                "objects: {} kinds of Impostor ({impostors:?}); a scene has at most one (the \
                 renderers bind one alpha mask)",
                impostors.len()
            ));
        }
        if triangles > MAX_TRIANGLES {
            return Err(format!(
                "objects: {triangles} triangles over both LODs of every object, at most \
                 {MAX_TRIANGLES}"
            ));
        }
        Ok(())
    }

    /// Model matrix of object `i`.
    pub fn model(&self, i: usize) -> Mat4 {
        let o = &self.objects[i];
        Mat4::from_translation(o.position.into()) * Mat4::from_scale(o.scale.into())
    }

    /// A SIMPLE-like scene (Scherzer & Wimmer 2008, Fig. 9): a grid of red spheres (LOD 0)
    /// turning into blue boxes (LOD 1) over a floor.
    pub fn simple() -> DemoScene {
        let mut objects: Vec<DemoObject> = (0..15)
            .map(|i| DemoObject {
                fine: Shape::Sphere {
                    rings: 16,
                    segments: 24,
                },
                coarse: Shape::Cube,
                fine_color: [0.9, 0.15, 0.1],
                coarse_color: [0.15, 0.3, 0.95],
                position: [(i % 5) as f32 * 2.2 - 4.4, 0.0, -((i / 5) as f32) * 2.5],
                scale: [0.8; 3],
                transition: true,
                sway: 0.0,
            })
            .collect();
        objects.push(scenery(
            [0.0, -1.0, -2.5],
            [8.0, 0.1, 5.0],
            [0.7, 0.7, 0.65],
        ));
        DemoScene {
            name: "simple".to_owned(),
            camera: DemoCamera {
                eye: [-1.0, 3.0, 7.5],
                target: [0.0, 0.0, -2.5],
                moving_eye: [1.2, 2.6, 6.0],
                fov_y: 0.8,
            },
            objects,
        }
    }

    /// Tree-like clusters (many small spheres, LOD 1 one blob) in front of a wall: the scene
    /// where see-through of a cross-fade shows.
    pub fn trees() -> DemoScene {
        let mut objects: Vec<DemoObject> = (0..8)
            .map(|i| {
                let x = (i % 4) as f32 * 1.7 - 2.55;
                let z = -((i / 4) as f32) * 1.8 + 0.3 * (i % 2) as f32;
                DemoObject {
                    fine: Shape::Tree { puffs: 7, rings: 8 },
                    coarse: Shape::Tree { puffs: 1, rings: 4 },
                    fine_color: [0.15, 0.65, 0.2],
                    coarse_color: [0.1, 0.45, 0.35],
                    position: [x, 0.0, z],
                    scale: [0.9; 3],
                    transition: true,
                    sway: 0.0,
                }
            })
            .collect();
        objects.push(scenery(
            [0.0, 0.5, -4.5],
            [6.0, 3.0, 0.1],
            [0.85, 0.85, 0.9],
        ));
        objects.push(scenery(
            [0.0, -1.0, -1.5],
            [6.0, 0.1, 4.0],
            [0.55, 0.45, 0.35],
        ));
        DemoScene {
            name: "trees".to_owned(),
            camera: DemoCamera {
                eye: [0.0, 1.2, 6.0],
                target: [0.0, 0.0, -1.0],
                moving_eye: [1.6, 1.5, 5.0],
                fov_y: 0.8,
            },
            objects,
        }
    }
}

impl DemoScene {
    /// The case engines have: a field of trees at many distances, of which a few objects are in
    /// transition at a time and cover a small part of the screen. Their LOD chains are the ones
    /// single-frame blends find hard: a near tree swaying in the wind (an animated LOD pair), a
    /// far tree whose coarse LOD is an alpha-tested billboard impostor, a sphere whose box LOD
    /// intersects it (corners outside, faces inside), and a flat sign whose two LODs are
    /// coplanar.
    pub fn field() -> DemoScene {
        let tree = |x: f32, z: f32, transition: bool| DemoObject {
            fine: Shape::Tree { puffs: 7, rings: 8 },
            coarse: Shape::Tree { puffs: 1, rings: 4 },
            fine_color: [0.15, 0.6, 0.2],
            coarse_color: [0.1, 0.45, 0.35],
            position: [x, 0.0, z],
            scale: [0.8; 3],
            transition,
            sway: 0.0,
        };
        let mut objects: Vec<DemoObject> = (0..30)
            .map(|i| {
                let (col, row) = ((i % 6) as f32, (i / 6) as f32);
                // Staggered rows from 3 to 19 units in front of the camera.
                let x = col * 2.4 - 6.0 + 0.9 * (row % 2.0);
                tree(x, 1.0 - row * 4.0, false)
            })
            .collect();
        // The near tree sways in the wind: an animated LOD pair.
        objects.push(DemoObject {
            sway: 0.12,
            ..tree(-1.3, 1.6, true)
        });
        // The far tree's coarse LOD is an alpha-tested billboard impostor.
        objects.push(DemoObject {
            coarse: Shape::Impostor { puffs: 7, rings: 8 },
            coarse_color: [0.1, 0.5, 0.25],
            ..tree(3.0, -13.0, true)
        });
        objects.push(DemoObject {
            fine: Shape::Sphere {
                rings: 16,
                segments: 24,
            },
            coarse: Shape::Box {
                half: [0.8, 0.8, 0.8],
            },
            fine_color: [0.9, 0.15, 0.1],
            coarse_color: [0.15, 0.3, 0.95],
            position: [0.6, 0.2, 2.0],
            scale: [0.45; 3],
            transition: true,
            sway: 0.0,
        });
        objects.push(DemoObject {
            fine: Shape::Box {
                half: [1.0, 0.6, 0.04],
            },
            coarse: Shape::Box {
                half: [1.0, 0.6, 0.04],
            },
            fine_color: [0.95, 0.8, 0.2],
            coarse_color: [0.9, 0.45, 0.1],
            position: [-4.2, 0.4, -4.0],
            scale: [1.0; 3],
            transition: true,
            sway: 0.0,
        });
        objects.push(scenery(
            [0.0, -1.0, -8.0],
            [14.0, 0.1, 14.0],
            [0.45, 0.4, 0.3],
        ));
        DemoScene {
            name: "field".to_owned(),
            camera: DemoCamera {
                eye: [0.0, 1.6, 5.5],
                target: [0.0, 0.0, -6.0],
                moving_eye: [1.4, 1.9, 4.5],
                fov_y: 0.8,
            },
            objects,
        }
    }
}

fn scenery(position: [f32; 3], scale: [f32; 3], color: [f32; 3]) -> DemoObject {
    DemoObject {
        fine: Shape::Cube,
        coarse: Shape::Cube,
        fine_color: color,
        coarse_color: color,
        position,
        scale,
        transition: false,
        sway: 0.0,
    }
}
