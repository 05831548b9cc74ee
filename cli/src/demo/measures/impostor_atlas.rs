//! The picture of a scene's octahedral impostor atlas, for the report.

use std::path::Path;

use serde::Serialize;

use crate::demo::error::{DemoError, save};
use crate::demo::fixtures::render::SceneRenderer;

/// A scene's octahedral impostor atlas, as the report shows it.
#[derive(Clone, Debug, Serialize)]
pub struct AtlasFigure {
    /// The scene.
    pub scene: String,
    /// The picture of its colour atlas, relative to the output folder.
    pub picture: String,
    /// Frames per side.
    pub frames: u32,
    /// Texels per frame side.
    pub frame_size: u32,
    /// Whether the frames cover the upper hemisphere of directions (else the whole sphere).
    pub hemi: bool,
}

/// Writes `atlas/<scene>.png`, the colour atlas of the scene `renderer` draws, when it has one.
pub fn write(
    renderer: &SceneRenderer,
    scene: &str,
    out: &Path,
) -> Result<Option<AtlasFigure>, DemoError> {
    let Some((picture, layout)) = renderer.impostor_atlas() else {
        return Ok(None);
    };
    let path = format!("atlas/{scene}.png");
    save(picture, &out.join(&path))?;
    Ok(Some(AtlasFigure {
        scene: scene.to_owned(),
        picture: path,
        frames: layout.frames,
        frame_size: layout.frame_size,
        hemi: layout.shape.is_hemi(),
    }))
}
