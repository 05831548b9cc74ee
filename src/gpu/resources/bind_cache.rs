//! [`BindGroupCache`]: the bind groups a pass made, kept while the textures they bind are the
//! same, so that a recording makes none.

use std::sync::{Mutex, PoisonError};

use crate::gpu::GpuError;

/// One kept bind group and what it binds.
#[derive(Debug)]
struct Kept {
    textures: Vec<wgpu::Texture>,
    views: Vec<wgpu::TextureView>,
    group: wgpu::BindGroup,
}

/// Bind groups by the textures (and texture views) they bind: a pass records with the kept one
/// where the textures are those of an earlier recording (wgpu compares them by identity), and
/// makes and keeps one otherwise. It keeps `capacity` of them, the least recently used going
/// first, and with them their textures; a new group whose first texture (the pass's target-sized
/// input) has another size than a kept one's drops that one, so an engine's buffers from before
/// a resize are not kept alive.
#[derive(Debug)]
pub(crate) struct BindGroupCache {
    kept: Mutex<Vec<Kept>>,
    capacity: usize,
}

impl BindGroupCache {
    /// A cache of at most `capacity` bind groups (at least 1).
    pub(crate) fn new(capacity: usize) -> Self {
        Self {
            kept: Mutex::new(Vec::new()),
            capacity: capacity.max(1),
        }
    }

    /// The bind group of `textures` and `views`: the kept one, or `make`'s, then kept.
    pub(crate) fn get_or_make(
        &self,
        textures: &[&wgpu::Texture],
        views: &[&wgpu::TextureView],
        make: impl FnOnce() -> Result<wgpu::BindGroup, GpuError>,
    ) -> Result<wgpu::BindGroup, GpuError> {
        let mut kept = self.kept.lock().unwrap_or_else(PoisonError::into_inner);
        let same = |k: &Kept| {
            k.textures.len() == textures.len()
                && k.views.len() == views.len()
                && k.textures.iter().zip(textures).all(|(a, b)| a == *b)
                && k.views.iter().zip(views).all(|(a, b)| a == *b)
        };
        if let Some(at) = kept.iter().position(same) {
            // Least recently used goes first: a hit moves to the back.
            let hit = kept.remove(at);
            let group = hit.group.clone();
            kept.push(hit);
            return Ok(group);
        }
        let group = make()?;
        // A first texture of another size than the new one's: the engine resized its targets,
        // and what it bound before will not come back.
        if let Some(first) = textures.first() {
            kept.retain(|k| k.textures.first().is_none_or(|t| t.size() == first.size()));
        }
        if kept.len() >= self.capacity {
            kept.remove(0);
        }
        kept.push(Kept {
            textures: textures.iter().map(|t| (*t).clone()).collect(),
            views: views.iter().map(|v| (*v).clone()).collect(),
            group: group.clone(),
        });
        Ok(group)
    }
}
