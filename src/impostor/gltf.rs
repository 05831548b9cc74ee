//! What a glTF file says of an impostor level: the `extras` of its card node, written by
//! `lodkit lod --impostor` and read by a loader (lodkit_bevy's), one definition for both.

use super::{ImpostorError, ImpostorLayout, ImpostorShape};

/// A card node's `extras["lodkit_impostor"]` ([`IMPOSTOR_GLTF_EXTRAS_KEY`](super::IMPOSTOR_GLTF_EXTRAS_KEY)):
/// the layout in the mesh's own space and the document's indices of the two atlas images (level
/// 0 of each, frames padded; a loader builds the mip chains with [`ImpostorAtlas::from_level0`](super::ImpostorAtlas::from_level0)).
///
/// ```json
/// {"frames": 12, "frame_size": 128, "shape": "hemi", "center": [0.0, 1.0, 0.0],
///  "radius": 1.5, "color_image": 7, "normal_depth_image": 8}
/// ```
///
/// Fields it does not know are ignored (a later writer may add some).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ImpostorGltfExtras {
    /// Frames per side.
    pub frames: u32,
    /// Texels per side of one frame.
    pub frame_size: u32,
    /// `"hemi"` or `"full"`.
    #[serde(with = "shape_name")]
    pub shape: ImpostorShape,
    /// The bounding sphere's centre (the mesh's space).
    pub center: [f32; 3],
    /// The bounding sphere's radius.
    pub radius: f32,
    /// The colour atlas's image (sRGB colour, alpha coverage).
    pub color_image: usize,
    /// The normal and depth atlas's image (linear).
    pub normal_depth_image: usize,
}

impl ImpostorGltfExtras {
    /// The extras of an impostor of `layout` whose atlases are images `color_image` and
    /// `normal_depth_image`.
    pub fn new(layout: &ImpostorLayout, color_image: usize, normal_depth_image: usize) -> Self {
        Self {
            frames: layout.frames,
            frame_size: layout.frame_size,
            shape: layout.shape,
            center: layout.center,
            radius: layout.radius,
            color_image,
            normal_depth_image,
        }
    }

    /// The layout, checked ([`ImpostorLayout::validate`]).
    pub fn layout(&self) -> Result<ImpostorLayout, ImpostorError> {
        let layout = ImpostorLayout {
            frames: self.frames,
            frame_size: self.frame_size,
            shape: self.shape,
            center: self.center,
            radius: self.radius,
        };
        layout.validate()?;
        Ok(layout)
    }
}

/// `ImpostorShape` as glTF extras spell it: `"hemi"`, `"full"`.
mod shape_name {
    use super::ImpostorShape;

    pub fn serialize<S: serde::Serializer>(shape: &ImpostorShape, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(match shape {
            ImpostorShape::Hemi => "hemi",
            ImpostorShape::Full => "full",
        })
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<ImpostorShape, D::Error> {
        let name: String = serde::Deserialize::deserialize(d)?;
        match name.as_str() {
            "hemi" => Ok(ImpostorShape::Hemi),
            "full" => Ok(ImpostorShape::Full),
            other => Err(serde::de::Error::invalid_value(
                serde::de::Unexpected::Str(other),
                &"\"hemi\" or \"full\"",
            )),
        }
    }
}
