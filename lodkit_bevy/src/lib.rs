//! # lodkit_bevy
//!
//! [lodkit](https://docs.rs/lodkit) in Bevy 0.20: its WESL shader modules as Bevy shader assets, and
//! its techniques as plugins.
//!
//! - [`LodkitShadersPlugin`]: every `lodkit::` WESL module becomes a `Shader` asset, so your
//!   materials and post-processing shaders can `import lodkit::screen_door::screen_door_keep;`,
//!   `import lodkit::bilateral::bilateral_upsample_at;`, and so on.
//! - [`FramebufferLodPlugin`] with the [`FramebufferLod`] camera component: geometry-aware
//!   framebuffer LOD (Yang, Sander & Lawrence 2008). Your expensive effect (an asset type with
//!   its own bindings, like a material: [`framebuffer_lod::FramebufferLodEffect`]) runs at 1/r
//!   resolution, lodkit's bilateral upsample rebuilds it from the depth and normal prepass
//!   without bleeding across edges, and lodkit's controller can hold a frame-time target by
//!   choosing r every frame. See [`framebuffer_lod`].
//! - [`FrameSequentialLodPlugin`] with the [`FrameSequentialLod`] camera component and
//!   [`FrameSequentialGroup`](frame_sequential::FrameSequentialGroup) entities: smooth discrete
//!   LOD transitions (Scherzer & Wimmer 2008). A group in transition draws one of its two
//!   levels per frame and a combine pass merges consecutive frames, reprojected with the main
//!   pass's depth and the camera's and groups' motion (no prepass needed): less pop than Bevy's
//!   crossfade, one level drawn per frame. See [`frame_sequential`] for the figures against
//!   Bevy's crossfade in an app with and without a prepass. Levels take the app's own
//!   `StandardMaterial`s; [`gltf_lod`] makes groups of glTF files with `MSFT_lod` levels as
//!   Bevy's loader spawns them, and [`auto_lod::AutoLod`] of any entity with a mesh, its levels
//!   built in the background.
//! - [`ImpostorPlugin`](impostor::ImpostorPlugin) with [`ImpostorMaterial`](impostor::ImpostorMaterial):
//!   octahedral impostors baked by lodkit, drawn as a Bevy material lit by Bevy's PBR lighting,
//!   the last level of a chain past the meshes. See [`impostor`].
//!
//! lodkit is used with `default-features = false`: it brings no naga of its own; Bevy links its
//! WESL modules (wesl-rs), as it links its own.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use lodkit_bevy::prelude::*;
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, LodkitShadersPlugin, FramebufferLodPlugin))
//!     .run();
//! ```

#![warn(missing_docs)]

#[cfg(feature = "lod_chain")]
pub mod auto_lod;
pub mod frame_sequential;
pub mod framebuffer_lod;
#[cfg(feature = "gltf")]
pub mod gltf_lod;
pub mod impostor;
#[cfg(feature = "lod_chain")]
pub mod lod_chain;
mod shaders;

pub use frame_sequential::{FrameSequentialLod, FrameSequentialLodPlugin};
pub use framebuffer_lod::{FramebufferLod, FramebufferLodPlugin};
pub use shaders::{LodkitShaders, LodkitShadersPlugin};

/// The plugins, components and settings an app uses.
pub mod prelude {
    #[cfg(feature = "lod_chain")]
    pub use crate::auto_lod::{AutoLod, AutoLodStatus};
    pub use crate::frame_sequential::{
        FrameSequentialExtension, FrameSequentialGroup, FrameSequentialLevels, FrameSequentialLod,
        FrameSequentialLodPlugin, FrameSequentialMaterial, FrameSequentialStats,
        FrameSequentialSystems, LevelMaterial, LodLevel, LodLevels, OlderCoverage, VisibilitySpace,
    };
    pub use crate::framebuffer_lod::{
        FrameTimeSource, FramebufferLod, FramebufferLodCapabilities, FramebufferLodComposite,
        FramebufferLodEffect, FramebufferLodEffectHandle, FramebufferLodEffectPlugin,
        FramebufferLodFrameTimes, FramebufferLodPlugin, FramebufferLodResolution,
        FramebufferLodState, FramebufferLodSystems, FramebufferLodUpsample, FramerateTarget,
    };
    pub use crate::impostor::{ImpostorMaterial, ImpostorPlugin};
    pub use crate::shaders::LodkitShadersPlugin;
}
