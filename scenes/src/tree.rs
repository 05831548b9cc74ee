//! A tree with alpha-masked leaf cards and its base colour texture: what impostors are made for
//! (the objects of a forest), built from a seed so a test and the demo draw the same one.

use glam::{Quat, Vec2, Vec3};
use lodkit::gpu::impostor::{ImpostorMaterial, ImpostorMesh, ImpostorPart, ImpostorTexture};

/// Texels per side of [`LeafyTree::texture`].
pub const TREE_TEXTURE_SIZE: u32 = 64;

/// A trunk and leaf cards in one indexed mesh, with the texture its material samples: the left
/// half holds a leaf (alpha 1 inside, 0 outside and in a round hole), the right half the bark
/// (opaque). Drawn double-sided with an alpha cutoff of 0.5.
#[derive(Clone, Debug, PartialEq)]
pub struct LeafyTree {
    /// Vertex positions (object space, the trunk's foot at the origin, y up).
    pub positions: Vec<[f32; 3]>,
    /// Vertex normals.
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates.
    pub uvs: Vec<[f32; 2]>,
    /// Triangle list.
    pub indices: Vec<u32>,
    /// The base colour texture, RGBA8 sRGB, [`TREE_TEXTURE_SIZE`] a side, row 0 at the top.
    pub texture: Vec<u8>,
}

impl LeafyTree {
    /// A tree of `leaves` cards scattered through a crown, placed by `seed`.
    pub fn new(leaves: u32, seed: u32) -> Self {
        let mut tree = Self {
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            indices: Vec::new(),
            texture: texture(),
        };
        // The trunk: four sides of a square prism, bark uvs.
        let (w, h) = (0.08, 1.3);
        for k in 0..4 {
            let a = Quat::from_rotation_y(k as f32 * std::f32::consts::FRAC_PI_2);
            let n = a * Vec3::Z;
            let right = a * Vec3::X;
            let corners = [
                n * w - right * w,
                n * w + right * w,
                n * w + right * w + Vec3::Y * h,
                n * w - right * w + Vec3::Y * h,
            ];
            tree.quad(corners, n, [Vec2::new(0.75, 0.5); 4]);
        }
        let mut state = seed.wrapping_mul(0x9e37_79b9) | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / u32::MAX as f32
        };
        let crown = Vec3::new(0.0, 1.55, 0.0);
        for _ in 0..leaves {
            let dir = Vec3::new(next() * 2.0 - 1.0, next() * 1.6 - 0.8, next() * 2.0 - 1.0);
            let centre = crown + dir.clamp_length_max(1.0) * Vec3::new(0.75, 0.5, 0.75);
            let turn = Quat::from_euler(
                glam::EulerRot::YXZ,
                next() * std::f32::consts::TAU,
                (next() - 0.5) * 2.0,
                (next() - 0.5) * 1.0,
            );
            let (right, up) = (turn * Vec3::X * 0.28, turn * Vec3::Y * 0.2);
            let uvs = [
                Vec2::new(0.0, 1.0),
                Vec2::new(0.5, 1.0),
                Vec2::new(0.5, 0.0),
                Vec2::new(0.0, 0.0),
            ];
            let corners = [
                centre - right - up,
                centre + right - up,
                centre + right + up,
                centre - right + up,
            ];
            tree.quad(corners, turn * Vec3::Z, uvs);
        }
        tree
    }

    fn quad(&mut self, corners: [Vec3; 4], normal: Vec3, uvs: [Vec2; 4]) {
        let base = self.positions.len() as u32;
        for (p, uv) in corners.iter().zip(uvs) {
            self.positions.push(p.to_array());
            self.normals.push(normal.to_array());
            self.uvs.push(uv.to_array());
        }
        self.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }

    /// Its material: the texture, alpha-masked at 0.5, double-sided.
    pub fn material(&self) -> ImpostorMaterial<'_> {
        ImpostorMaterial {
            base_color_texture: Some(ImpostorTexture {
                width: TREE_TEXTURE_SIZE,
                height: TREE_TEXTURE_SIZE,
                rgba8: &self.texture,
            }),
            alpha_cutoff: Some(0.5),
            double_sided: true,
            ..Default::default()
        }
    }

    /// The whole tree with its material: what an impostor of it is baked from.
    pub fn part(&self) -> ImpostorPart<'_> {
        ImpostorPart {
            mesh: ImpostorMesh {
                positions: &self.positions,
                indices: &self.indices,
                normals: Some(&self.normals),
                uvs: Some(&self.uvs),
            },
            material: self.material(),
        }
    }

    /// Triangles in the mesh.
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }
}

/// The leaf (left half) and bark (right half) texture.
fn texture() -> Vec<u8> {
    let s = TREE_TEXTURE_SIZE;
    let mut out = Vec::with_capacity((s * s * 4) as usize);
    for y in 0..s {
        for x in 0..s {
            let (u, v) = ((x as f32 + 0.5) / s as f32, (y as f32 + 0.5) / s as f32);
            if u >= 0.5 {
                out.extend([110, 80, 50, 255]);
                continue;
            }
            // The leaf: an ellipse over the left half, a round hole off its centre.
            let p = Vec2::new((u - 0.25) / 0.25, (v - 0.5) / 0.5);
            let hole = (p - Vec2::new(0.3, 0.2)).length() < 0.25;
            let inside = p.length() < 0.95 && !hole;
            let green = (120.0 + 60.0 * p.y) as u8;
            out.extend([50, green, 40, if inside { 255 } else { 0 }]);
        }
    }
    out
}
