//! What the combine knows of a frame, laid out by lodkit
//! (`lodkit::combine_coverage::CombineData`, the data texture `combine_pixel` reads).

use bevy::prelude::*;
use lodkit::combine_coverage::{
    CombineData, CombineDataDescriptor, CombineDataError, CombineObjectData, CoverageRoute,
};

use super::rects::to_lodkit;
use super::view::FrameSequentialView;

/// What the combine knows this frame, laid out by lodkit (`CombineData`): the camera's
/// reprojection, whether motion vectors and the older-level depth pass are read (`exact`), and
/// per t-instance drawn this frame its reprojection (the group's motion where it moved), the
/// threshold its older level is displayed at (screen-anchored pattern) and its coverage route:
/// with `exact`, its older level's silhouette where it has one, else the depth pass; otherwise
/// the estimate.
pub(super) fn combine_data(
    view: &FrameSequentialView,
    exact: bool,
    height: u32,
) -> Result<CombineData, CombineDataError> {
    let found = |list: &[(u32, Mat4)], id| list.iter().find(|&&(i, _)| i == id).map(|&(_, m)| m);
    let objects: Vec<CombineObjectData> = view
        .transition_ids
        .iter()
        .map(|&id| {
            let silhouette = view.silhouettes.iter().find(|(i, _)| *i == id);
            let route = match silhouette {
                _ if !exact => CoverageRoute::Estimate,
                Some((_, segments)) => CoverageRoute::Silhouette(segments),
                None => CoverageRoute::DepthPass,
            };
            CombineObjectData {
                id,
                new_to_old: to_lodkit(
                    found(&view.object_new_to_old, id).unwrap_or(view.new_to_old),
                ),
                older_tau: view
                    .older_tau
                    .iter()
                    .find(|&&(i, _)| i == id)
                    .map(|&(_, t)| t),
                route,
            }
        })
        .collect();
    CombineData::new(&CombineDataDescriptor {
        new_to_old: to_lodkit(view.new_to_old),
        object_motion: view.motion_vectors,
        level_depth: exact,
        height,
        objects: &objects,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use lodkit::combine_coverage::{
        COMBINE_ANCHORED, COMBINE_KNOWN, COMBINE_LEVEL_DEPTH, COMBINE_OBJECT_MOTION,
        COMBINE_ROUTE_DEPTH_PASS, COMBINE_ROUTE_SILHOUETTE, combine_object,
    };

    fn view() -> FrameSequentialView {
        FrameSequentialView {
            view_from_world: Mat4::IDENTITY,
            clip_from_view: Mat4::IDENTITY,
            new_to_old: Mat4::from_translation(Vec3::new(0.25, 0.0, 0.0)),
            transition_ids: vec![2, 5],
            object_new_to_old: vec![(5, Mat4::from_scale(Vec3::splat(2.0)))],
            drawn_tau_next: Vec::new(),
            older_tau: vec![(2, -0.375)],
            older_levels: Vec::new(),
            silhouettes: vec![(
                2,
                vec![
                    [1.0, 1.0, 1.0, 3.0],
                    [1.0, 3.0, 3.0, 3.0],
                    [3.0, 3.0, 3.0, 1.0],
                    [3.0, 1.0, 1.0, 1.0],
                ],
            )],
            exact_coverage: true,
            motion_vectors: true,
            rects: Vec::new(),
            keep: true,
            buffer: 0,
        }
    }

    #[test]
    fn each_t_instance_gets_its_route_matrix_and_threshold() {
        let data = combine_data(&view(), true, 8).unwrap();
        let frame = combine_object(&data.texels, 0);
        assert_eq!(
            frame.flags,
            COMBINE_KNOWN | COMBINE_OBJECT_MOTION | COMBINE_LEVEL_DEPTH
        );
        assert_eq!(frame.new_to_old.w_axis.x, 0.25);
        // Id 2: a silhouette and a screen-anchored older level at its threshold.
        let two = combine_object(&data.texels, 2);
        assert_eq!(
            two.flags,
            COMBINE_KNOWN | COMBINE_ANCHORED | COMBINE_ROUTE_SILHOUETTE
        );
        assert_eq!(two.older_tau, -0.375);
        assert_eq!(two.new_to_old.w_axis.x, 0.25, "not moved: the camera's");
        // Id 5: no silhouette, so the depth pass; its group moved.
        let five = combine_object(&data.texels, 5);
        assert_eq!(five.flags, COMBINE_KNOWN | COMBINE_ROUTE_DEPTH_PASS);
        assert_eq!(five.new_to_old.x_axis.x, 2.0);
        // Not in transition: unknown.
        assert_eq!(combine_object(&data.texels, 3).flags, 0);
    }

    #[test]
    fn without_exact_coverage_every_level_is_estimated() {
        let data = combine_data(&view(), false, 8).unwrap();
        assert_eq!(
            combine_object(&data.texels, 0).flags,
            COMBINE_KNOWN | COMBINE_OBJECT_MOTION
        );
        for id in [2, 5] {
            let flags = combine_object(&data.texels, id).flags;
            assert_eq!(
                flags & (COMBINE_ROUTE_SILHOUETTE | COMBINE_ROUTE_DEPTH_PASS),
                0,
                "id {id}"
            );
            assert_ne!(flags & COMBINE_KNOWN, 0, "id {id}");
        }
    }

    #[test]
    fn a_matrix_that_is_not_finite_is_refused() {
        let mut bad = view();
        bad.object_new_to_old[0].1.x_axis.x = f32::NAN;
        assert_eq!(
            combine_data(&bad, true, 8).unwrap_err(),
            CombineDataError::NotFinite {
                index: 1,
                what: "new_to_old"
            }
        );
    }
}
