//! The main-world side: level entities, selection from the camera, lodkit's transition
//! scheduler, and what the render world needs of the frame (the combine's rectangles and the
//! reprojection matrix).

use std::time::Duration;

use bevy::camera::CameraUpdateSystems;
use bevy::camera::visibility::VisibilitySystems;
use bevy::core_pipeline::prepass::{
    DeferredPrepass, DepthPrepass, MotionVectorPrepass, NormalPrepass,
};
use bevy::log::warn_once;
use bevy::mesh::MeshTag;
use bevy::mesh::skinning::SkinnedMesh;
use bevy::platform::time::Instant;
use bevy::prelude::*;
use bevy::render::render_resource::{Face, TextureUsages};
use bevy::transform::TransformSystems;
use lodkit::combine::{ScreenRect, merge_rects};
use lodkit::frame_sequential::{Drive, TransitionScheduler};
use lodkit::reproject::new_to_old_matrix;
use lodkit::select::{LodCamera, LodSelection};

use super::camera::{FrameSequentialDefaultCamera, default_camera};
use super::dither::{Fallback, dither_draws};
use super::drawer::{
    DrawerQuery, FrameSequentialLevels, Scheduler, drawn, show, spawn_drawer, spawn_levels,
};
use super::level_material::{
    ApplyDrawerMaterials, DeriveMaterials, DerivedMaterials, DrawerMaterial, add_level_material,
};
use super::rects::{Bounds, group_hull, group_rect, level_bounds, merge_rows, to_lodkit};
use super::silhouette::{OutlineView, Surfaces, forget_changed_meshes, outline};
use super::tag::{decode_tag, encode_tag};
use super::view::{FrameSequentialView, OlderLevel};
use super::{
    CombineRegion, FrameSequentialExtension, FrameSequentialGroup, FrameSequentialLod,
    FrameSequentialMaterial, FrameSequentialSystems, LodLevels, OlderCoverage, VisibilitySpace,
};

pub(super) fn build(app: &mut App) {
    app.init_resource::<Scheduler>()
        .init_resource::<FrameSequentialDefaultCamera>()
        .init_resource::<FrameSequentialStats>()
        .init_resource::<Surfaces>()
        .add_systems(
            PostUpdate,
            (
                default_camera,
                configure_depth_copies,
                spawn_levels,
                forget_changed_meshes,
                update,
            )
                .chain()
                .in_set(FrameSequentialSystems),
        )
        .configure_sets(
            PostUpdate,
            (
                FrameSequentialSystems
                    .after(TransformSystems::Propagate)
                    .after(CameraUpdateSystems)
                    .before(VisibilitySystems::VisibilityPropagate),
                DeriveMaterials
                    .in_set(FrameSequentialSystems)
                    .after(spawn_levels)
                    .before(update),
                ApplyDrawerMaterials
                    .in_set(FrameSequentialSystems)
                    .after(update),
            ),
        );
    add_level_material::<StandardMaterial, FrameSequentialExtension>(app);
}

/// What the last frame's selection did, for reports and tests.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct FrameSequentialStats {
    /// Groups in transition this frame.
    pub in_transition: usize,
    /// Pixels the combine pass covers this frame (the area of its hulls' rows and its
    /// rectangles).
    pub combine_pixels: u64,
    /// Frames the scheduler has run.
    pub frames: u64,
    /// Whether the render world keeps this frame (copies its color and depth) for the next
    /// frame's combine: while a group is in transition, and the frame before one begins.
    pub frame_kept: bool,
    /// Frames kept so far (of [`frames`](Self::frames)).
    pub frames_kept: u64,
    /// CPU time this frame spent finding the older levels' silhouettes
    /// ([`OlderCoverage::Silhouette`]) and, for the combine's hulls
    /// ([`CombineRegion::Hulls`]), those of the levels drawn, building a mesh's surface the
    /// first time it is needed included.
    pub silhouette_time: Duration,
    /// Triangles whose facing this frame's silhouettes tested (the drawn levels' included).
    pub silhouette_triangles: u64,
}

/// The combine copies the main pass's depth (the older frame's, next frame): Bevy's depth
/// texture allows copies only with a depth prepass, unless the camera asks for them.
fn configure_depth_copies(mut cameras: Query<&mut Camera3d, With<FrameSequentialLod>>) {
    for mut camera in &mut cameras {
        let usages = TextureUsages::from(camera.depth_texture_usages);
        if !usages.contains(TextureUsages::COPY_SRC) {
            camera.depth_texture_usages = (usages | TextureUsages::COPY_SRC).into();
        }
    }
}

/// Brings the scheduler's view of a group in line with lodkit's selection. A transition the
/// selection starts begins only where `may_begin` (the older frame was kept); else this returns
/// true: keep this frame, and the transition begins next frame.
fn reconcile(
    scheduler: &mut TransitionScheduler,
    levels: &mut FrameSequentialLevels,
    selection: &LodSelection,
    may_begin: bool,
) -> bool {
    let key = *levels
        .key
        .get_or_insert_with(|| scheduler.insert(selection.current));
    if !scheduler.in_transition(key) {
        // The scheduler ended it (progress reached 1 last frame).
        levels.transition = None;
    }
    if let Some((from, to)) = levels.transition {
        if selection.current == from && selection.next == Some(to) {
            let _ = scheduler.set_progress(key, selection.transition);
            return false;
        }
        if selection.current == to && selection.next.is_none() {
            // Done: the scheduler shows `to` whole this frame and settles on it.
            let _ = scheduler.set_progress(key, 1.0);
            return false;
        }
        // The selection turned back or jumped: settle where it is now.
        let _ = scheduler.remove(key);
        levels.key = Some(scheduler.insert(selection.current));
        levels.transition = None;
    }
    let key = levels.key.expect("inserted above");
    let settled = scheduler
        .draw(key)
        .map(|d| d.lod)
        .unwrap_or(selection.current);
    if settled != selection.current {
        let _ = scheduler.remove(key);
        levels.key = Some(scheduler.insert(selection.current));
    }
    if let Some(next) = selection.next {
        if !may_begin {
            return true;
        }
        let key = levels.key.expect("inserted above");
        if scheduler
            .begin_transition(key, next, Drive::Progress)
            .is_ok()
        {
            let _ = scheduler.set_progress(key, selection.transition);
            levels.transition = Some((selection.current, next));
        }
    }
    false
}

type CameraQuery<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Camera,
        &'static GlobalTransform,
        &'static FrameSequentialLod,
        Option<&'static FrameSequentialView>,
        Option<&'static Msaa>,
        Has<MotionVectorPrepass>,
        Has<DepthPrepass>,
        Has<NormalPrepass>,
        Has<DeferredPrepass>,
    ),
>;

type GroupQuery<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static FrameSequentialGroup,
        &'static LodLevels,
        &'static GlobalTransform,
        &'static mut FrameSequentialLevels,
        Option<&'static SkinnedMesh>,
    ),
>;

/// Selects, schedules and shows the level each group draws this frame; hands the camera's
/// combine rectangles and reprojection to the render world.
#[allow(clippy::too_many_arguments)]
fn update(
    mut commands: Commands,
    time: Res<Time>,
    meshes: Res<Assets<Mesh>>,
    materials: Res<Assets<FrameSequentialMaterial>>,
    derived: Res<DerivedMaterials>,
    mut scheduler: ResMut<Scheduler>,
    mut stats: ResMut<FrameSequentialStats>,
    mut surfaces: ResMut<Surfaces>,
    cameras: CameraQuery,
    mut groups: GroupQuery,
    mut drawers: DrawerQuery,
    stale: Query<Entity, (With<FrameSequentialView>, Without<FrameSequentialLod>)>,
) {
    for camera in &stale {
        commands.entity(camera).remove::<FrameSequentialView>();
    }
    let Scheduler(scheduler, keys) = &mut *scheduler;
    keys.retain(|&(group, key)| {
        let live = groups.contains(group);
        if !live {
            let _ = scheduler.remove(key);
        }
        live
    });
    let Some((
        camera_entity,
        camera,
        camera_transform,
        settings,
        last,
        msaa,
        has_motion,
        has_depth,
        has_normal,
        has_deferred,
    )) = cameras.iter().find(|(_, c, ..)| c.is_active)
    else {
        return;
    };
    let prepass = has_motion || has_depth || has_normal || has_deferred;
    // The combine reads and copies the main pass per pixel: a multisampled camera gets no
    // combine; its groups are drawn through the screen-door dither, in the prepass too, or
    // switch at once where a level's prepass cannot drop the dither's pixels
    // (`dither::Fallback`).
    let multisampled = msaa.is_some_and(|m| *m != Msaa::Off);
    if multisampled {
        warn_once!(
            "FrameSequentialLod on a camera with MSAA: its LOD groups blend with lodkit's \
             complementary screen-door dither (Msaa::Off for the frame-sequential combine){}",
            if prepass {
                "; with the camera's prepass, levels whose material has a prepass shader of \
                 its own switch at once"
            } else {
                ""
            }
        );
        commands
            .entity(camera_entity)
            .remove::<FrameSequentialView>();
    }
    if cameras.iter().filter(|(_, c, ..)| c.is_active).count() > 1 {
        warn_once!("more than one active camera has FrameSequentialLod: the first one selects");
    }
    if stats.frames > 0 {
        scheduler.advance(time.delta_secs());
    }
    stats.frames = scheduler.frame() + 1;
    scheduler.set_schedule(settings.schedule);
    let view_from_world = camera_transform.to_matrix().inverse();
    let clip_from_view = camera.clip_from_view();
    let previous_view = last.map_or((view_from_world, clip_from_view), |l| {
        (l.view_from_world, l.clip_from_view)
    });
    let size = camera.physical_target_size().unwrap_or(UVec2::ONE);
    let lod_camera = LodCamera::new(
        glam::Vec3::from_array(camera_transform.translation().to_array()),
        to_lodkit(camera.clip_from_view()),
    );
    let object = settings.anchor == VisibilitySpace::Object;
    let mut rects = Vec::new();
    // The rows of the groups' combine hulls.
    let mut hull_rows = Vec::new();
    // The world motion of each t-instance that moved.
    let mut moved = Vec::new();
    let mut drawn_tau_next = Vec::new();
    let mut older_tau = Vec::new();
    let mut older_levels = Vec::new();
    let mut silhouettes = Vec::new();
    let mut silhouette_time = Duration::ZERO;
    let mut silhouette_triangles = 0;
    let mut in_transition = 0;
    let mut transition_ids = Vec::new();
    // The combine needs last frame's picture: a transition begins only after a frame that the
    // render world kept, and frames are kept only while a group is in transition or about to be.
    let older_kept = !multisampled && last.is_some_and(|l| l.keep);
    let mut keep_frame = false;
    for (entity, group, levels, transform, mut state, skin) in &mut groups {
        let state = &mut *state;
        let had_key = state.key;
        let model = transform.to_matrix();
        let scale = transform
            .to_scale_rotation_translation()
            .0
            .abs()
            .max_element();
        let distance = lod_camera.lod_distance(
            glam::Vec3::from_array(transform.translation().to_array()),
            scale,
            settings.settings.bias,
        );
        let selection = group.group.select(
            distance,
            &settings.settings,
            time.delta_secs(),
            &mut state.state,
        );
        // Only a group in transition (or starting one) needs to know: a settled group draws its
        // level whole either way.
        let transitioning = selection.next.is_some() || state.transition.is_some();
        // Whether a level blends, and whether a level's prepass would draw it whole.
        let (mut blending, mut whole) = (false, false);
        if transitioning {
            for looks in levels
                .0
                .iter()
                .filter_map(|l| derived.looks(&l.material, &materials))
            {
                blending |= looks.blends;
                whole |= !looks.prepass_dithers;
            }
        }
        // The levels' prepass drops the dither's pixels only on a multisampled camera (where
        // the dither is the rule; without MSAA it serves blending levels alone, and the
        // prepass of the group's other levels is Bevy's).
        let prepass_draws_whole = prepass && (!multisampled || whole);
        let fallback = Fallback::of(multisampled, blending, prepass_draws_whole);
        if blending {
            warn_once!(
                "a LOD group has a blending material (AlphaMode::Blend, ...), whose alpha cannot \
                 carry the combine's id word, or a masked one other than a StandardMaterial, \
                 whose coverage lodkit cannot repeat: {}",
                if fallback == Fallback::Dither {
                    "it blends with the screen-door dither"
                } else {
                    "with a prepass on the camera that draws its levels whole, it switches \
                     levels at once"
                }
            );
        }
        if fallback == Fallback::Dither {
            if let Some(key) = state.key.take() {
                let _ = scheduler.remove(key);
                keys.retain(|&(g, _)| g != entity);
            }
            state.transition = None;
            state.previous_model = Some(model);
            state.selection = Some(selection);
            state.drawn = selection.current;
            let [mut outgoing, incoming] = dither_draws(&selection);
            match (state.dither_entity, drawn(incoming, levels, &derived)) {
                (Some(drawer), _) => show(&mut drawers, drawer, incoming, levels, &derived),
                // The group's first dithered transition: its second drawer is spawned now, and
                // Bevy draws an entity from the frame after the one it was spawned in. This
                // frame the outgoing level is drawn whole (the transition starts a frame
                // late), or the pixels left to the incoming one would show what is behind.
                (None, Some((mesh, material, tag))) => {
                    outgoing = outgoing.map(|(level, _)| (level, 0));
                    let drawer = spawn_drawer(&mut commands, entity, mesh, skin);
                    // Transforms were propagated before this system: the new child gets its
                    // group's (its own is the identity), or it would be drawn at the origin
                    // this frame.
                    commands.entity(drawer).insert((
                        DrawerMaterial(Some(material)),
                        MeshTag::new(tag),
                        Visibility::Inherited,
                        *transform,
                    ));
                    state.dither_entity = Some(drawer);
                }
                (None, None) => {}
            }
            show(&mut drawers, state.entity, outgoing, levels, &derived);
            continue;
        }
        keep_frame |= reconcile(scheduler, state, &selection, older_kept && !blending);
        if state.key != had_key {
            keys.retain(|&(g, _)| g != entity);
            keys.extend(state.key.map(|k| (entity, k)));
        }
        let draw = state.key.and_then(|k| scheduler.draw(k).ok());
        let (lod, tag) = match draw {
            Some(d) => match encode_tag(d.id, d.tau, d.tau_next, object) {
                Some(tag) => (d.lod, tag),
                None => {
                    warn_once!(
                        "more than {} LOD groups in transition: the others switch at once",
                        super::MAX_TAG_ID
                    );
                    (if d.incoming { d.lod } else { selection.current }, 0)
                }
            },
            None => (selection.current, 0),
        };
        // An n-instance's tag is not 0 (it carries tau = 1): its id is.
        let (tag_id, _, tau_next, _) = decode_tag(tag);
        if tag_id != 0 {
            in_transition += 1;
            transition_ids.push(tag_id);
            if !object {
                drawn_tau_next.push((tag_id, tau_next));
                // The older buffer holds this id's other level when last frame drew the id: the
                // combine shows that level at this frame's threshold for it, exactly
                // complementary to the level drawn now. (Last frame's tau_next was a prediction
                // of this frame's progress; where it missed, pixels had both levels or neither.)
                if let Some(d) = draw.filter(|_| {
                    last.is_some_and(|l| l.drawn_tau_next.iter().any(|&(id, _)| id == tag_id))
                }) {
                    older_tau.push((
                        tag_id,
                        scheduler.schedule().threshold(d.progress, !d.incoming),
                    ));
                }
            }
            if state.bounds.is_none() {
                state.bounds = match group.bounds {
                    Some((lo, hi)) => Some(Bounds {
                        lo,
                        hi,
                        radius: (hi - lo).length() / 2.0,
                    }),
                    None => level_bounds(levels, &meshes),
                };
            }
            // The level this frame does not draw: the combine shows it from last frame's
            // picture, and the older-level depth pass draws where it is now.
            let other = state
                .transition
                .map(|(from, to)| if lod == from { to } else { from })
                .and_then(|other| levels.0.get(usize::from(other)));
            // Its combine hull's rows, where it has one.
            let mut hull = None;
            if let Some(other) = other.filter(|_| selection.visible && settings.coverage.is_exact())
            {
                let (cull_mode, alpha_test) = derived
                    .looks(&other.material, &materials)
                    .map_or((Some(Face::Back), None), |m| (m.cull_mode, m.alpha_test));
                // Where the level's silhouette can be had on the CPU (a closed triangle mesh
                // with its positions, culled as usual, not masked), it tells the coverage; else
                // the older-level depth pass draws the level (with its alpha test).
                let wants_outline = settings.coverage == OlderCoverage::Silhouette
                    && cull_mode != Some(Face::Front)
                    && alpha_test.is_none();
                let view = OutlineView {
                    clip_from_world: clip_from_view * view_from_world,
                    eye: camera_transform.translation(),
                    model,
                    size,
                };
                let mut outline_of = |mesh: &Handle<Mesh>| {
                    let start = Instant::now();
                    let outline = outline(&mut surfaces, &meshes, mesh.id(), &view);
                    silhouette_time += start.elapsed();
                    outline.map(|(segments, triangles)| {
                        silhouette_triangles += triangles;
                        segments
                    })
                };
                match wants_outline.then(|| outline_of(&other.mesh)) {
                    Some(Ok(segments)) => {
                        // The combine region: the hull of both levels' silhouettes, where the
                        // level drawn now has one too (and the group names no bounds of its
                        // own, which vertex animation may reach beyond the meshes).
                        let drawn = levels.0.get(usize::from(lod)).or(levels.0.last());
                        if settings.combine_region == CombineRegion::Hulls
                            && group.bounds.is_none()
                            && let Some(Ok(newer)) = drawn.map(|l| outline_of(&l.mesh))
                        {
                            hull = group_hull(&segments, &newer, size);
                        }
                        silhouettes.push((tag_id, segments));
                    }
                    _ => older_levels.push(OlderLevel {
                        mesh: other.mesh.id(),
                        world_from_local: model,
                        cull_mode,
                        alpha_test,
                    }),
                }
            }
            let previous = state.previous_model.unwrap_or(model);
            if previous != model {
                moved.push((tag_id, previous * model.inverse()));
            }
            match (hull, state.bounds) {
                (Some(rows), _) => hull_rows.extend(rows),
                (None, Some(bounds)) => {
                    rects.extend(group_rect(
                        bounds,
                        model,
                        view_from_world,
                        clip_from_view,
                        size,
                    ));
                    rects.extend(group_rect(
                        bounds,
                        previous,
                        previous_view.0,
                        previous_view.1,
                        size,
                    ));
                }
                (None, None) => rects.push(ScreenRect {
                    x: 0,
                    y: 0,
                    width: size.x,
                    height: size.y,
                }),
            }
        }
        state.previous_model = Some(model);
        state.selection = Some(selection);
        state.drawn = lod;
        let draw = selection.visible.then_some((lod, tag));
        show(&mut drawers, state.entity, draw, levels, &derived);
        if let Some(drawer) = state.dither_entity {
            show(&mut drawers, drawer, None, levels, &derived);
        }
    }
    // A rectangle and a row may overlap (groups with and without hulls): that pixel is combined
    // twice, to the same color.
    let mut rects = merge_rects(&rects);
    rects.extend(merge_rows(&hull_rows));
    stats.in_transition = in_transition;
    stats.silhouette_time = silhouette_time;
    stats.silhouette_triangles = silhouette_triangles;
    stats.frame_kept = !multisampled && (keep_frame || in_transition > 0);
    stats.frames_kept += u64::from(stats.frame_kept);
    stats.combine_pixels = rects.iter().map(ScreenRect::area).sum();
    // This frame's clip space to last frame's for a point that moved by `motion` (world).
    let reproject = |motion: Mat4| {
        let m = new_to_old_matrix(
            &to_lodkit(view_from_world),
            &to_lodkit(clip_from_view),
            &to_lodkit(previous_view.0 * motion),
            &to_lodkit(previous_view.1),
        );
        Mat4::from_cols_array(&m.to_cols_array())
    };
    let motion_vectors = settings.reprojection && has_motion;
    // The groups' matrices in both routes: without motion vectors their pixels are reprojected
    // with them; with motion vectors the combine still needs them to tell where a group moved
    // away from a pixel (the pixel then shows no trace of it).
    let (new_to_old, object_new_to_old) = if !settings.reprojection {
        (Mat4::IDENTITY, Vec::new())
    } else {
        let objects = moved
            .into_iter()
            .map(|(id, motion)| (id, reproject(motion)))
            .collect();
        (reproject(Mat4::IDENTITY), objects)
    };
    if multisampled {
        return;
    }
    commands.entity(camera_entity).insert(FrameSequentialView {
        view_from_world,
        clip_from_view,
        new_to_old,
        transition_ids,
        object_new_to_old,
        older_tau,
        drawn_tau_next,
        older_levels,
        silhouettes,
        exact_coverage: settings.coverage.is_exact(),
        motion_vectors,
        rects: rects
            .iter()
            .map(|r| URect::new(r.x, r.y, r.x + r.width, r.y + r.height))
            .collect(),
        keep: stats.frame_kept,
        buffer: scheduler.buffer_index(),
    });
}

#[cfg(test)]
#[path = "select_tests.rs"]
mod tests;
