//! The impostor as the last level of Bevy's own crossfade (`VisibilityRange`), from the first
//! view at the switch distance, held to the mesh alone and the impostor alone seen from the
//! same camera.

use bevy::camera::RenderTarget;
use bevy::camera::visibility::VisibilityRange;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;

use crate::frames::Frame;
use crate::headless::{capture, step};
use crate::{BACKGROUND, FOV};

/// Where the camera stands and what it draws into.
pub struct Shot {
    /// The image the camera draws into.
    pub target: Handle<Image>,
    /// The camera's position.
    pub eye: Vec3,
    /// The point it looks at (the bounding sphere's centre).
    pub center: Vec3,
    /// The near plane's distance.
    pub near: f32,
}

impl Shot {
    /// The example's camera at the shot (no MSAA, no tonemapping: the background exact).
    pub fn camera(&self) -> impl Bundle {
        let view = (self.eye - self.center).normalize();
        let up = if view.y.abs() > 0.95 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        (
            Camera3d::default(),
            Camera {
                clear_color: ClearColorConfig::Custom(Color::srgb_u8(
                    BACKGROUND[0],
                    BACKGROUND[1],
                    BACKGROUND[2],
                )),
                ..default()
            },
            Projection::Perspective(PerspectiveProjection {
                fov: FOV.to_radians(),
                near: self.near,
                ..default()
            }),
            RenderTarget::from(self.target.clone()),
            Msaa::Off,
            Tonemapping::None,
            DebandDither::Disabled,
            Transform::from_translation(self.eye).looking_at(self.center, up),
        )
    }
}

/// The mesh alone and the impostor alone from the shot, and which pixels show the tree.
pub struct References<'a> {
    /// The mesh alone.
    pub mesh: &'a Frame,
    /// The impostor alone.
    pub impostor: &'a Frame,
    /// Which pixels of a frame show the tree.
    pub coverage: &'a dyn Fn(&Frame) -> Vec<bool>,
}

/// Bevy's crossfade at its margin's midpoint.
pub struct Crossfade {
    /// Pixels both cover alone that show the background with both fading.
    pub see_through: usize,
    /// The share of its own pixels the impostor keeps fading in alone.
    pub kept: f32,
    /// Pixels of the crossfade that differ from the mesh alone.
    pub differs: usize,
}

/// Bevy's own crossfade (`VisibilityRange`): the mesh (`entities[0]`) fading out, the impostor
/// (`entities[1]`) fading in over the same margin around the camera. Bevy's dither gives the
/// two complementary pixels, so every pixel both cover alone shows one of them. Leaves both
/// entities hidden, without ranges.
pub fn visibility_range(
    app: &mut App,
    shot: &Shot,
    [tree, impostor]: [Entity; 2],
    references: &References,
) -> Result<Crossfade, (u8, String)> {
    let d0 = shot.eye.length(); // VisibilityRange measures from the entity's origin.
    let margin = (d0 * 0.9)..(d0 * 1.1);
    let world = app.world_mut();
    world.entity_mut(tree).insert((
        Visibility::Visible,
        VisibilityRange {
            start_margin: 0.0..0.0,
            end_margin: margin.clone(),
            use_aabb: false,
        },
    ));
    world.entity_mut(impostor).insert((
        Visibility::Visible,
        VisibilityRange {
            start_margin: margin,
            end_margin: 1e9..1e9,
            use_aabb: false,
        },
    ));
    let camera = world.spawn(shot.camera()).id();
    step(app);
    let faded = capture(app, &shot.target).map_err(|e| (1, e))?;
    // The impostor's half alone: the dither keeps part of its pixels.
    app.world_mut().entity_mut(tree).insert(Visibility::Hidden);
    step(app);
    let fading_in = capture(app, &shot.target).map_err(|e| (1, e))?;
    let world = app.world_mut();
    world.despawn(camera);
    for entity in [tree, impostor] {
        world
            .entity_mut(entity)
            .insert(Visibility::Hidden)
            .remove::<VisibilityRange>();
    }
    let coverage = references.coverage;
    let (m, i, f) = (
        coverage(references.mesh),
        coverage(references.impostor),
        coverage(&faded),
    );
    let see_through = (0..f.len()).filter(|&p| m[p] && i[p] && !f[p]).count();
    let at = |frame: &Frame, p: usize| frame.rgb(p as u32 % frame.width, p as u32 / frame.width);
    let differs = (0..f.len())
        .filter(|&p| f[p] && at(&faded, p) != at(references.mesh, p))
        .count();
    let kept = coverage(&fading_in).iter().filter(|c| **c).count() as f32
        / i.iter().filter(|c| **c).count().max(1) as f32;
    println!(
        "crossfade through Bevy's VisibilityRange at its midpoint: {} px covered, {differs} differ \
         from the mesh alone, {see_through} px where both cover alone show neither; the impostor \
         fading in alone keeps {kept:.2} of its pixels",
        f.iter().filter(|c| **c).count()
    );
    Ok(Crossfade {
        see_through,
        kept,
        differs,
    })
}
