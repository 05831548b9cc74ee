//! The CPU steps of a bake: the atlas images, padding each frame's empty texels with its
//! nearest covered texel (so filtering and mipmaps never blend the background's colour, normal
//! or depth into the object's edge), and the mip chain that keeps frames whole.

use super::{ImpostorError, ImpostorLayout};

/// A square image of RGBA floats, row-major from the top row.
#[derive(Clone, Debug, PartialEq)]
pub struct ImpostorImage {
    /// Texels per side.
    pub size: u32,
    /// `size * size` texels.
    pub texels: Vec<[f32; 4]>,
}

impl ImpostorImage {
    /// An image of `size x size` texels, all `value`.
    pub fn filled(size: u32, value: [f32; 4]) -> Self {
        Self {
            size,
            texels: vec![value; (size as usize) * (size as usize)],
        }
    }

    /// The texel at column `x`, row `y`.
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        self.texels[(y * self.size + x) as usize]
    }

    /// The texels as sRGB RGBA8: colour through the sRGB transfer function, alpha linear
    /// (what an `Rgba8UnormSrgb` texture or a PNG of the colour atlas holds).
    pub fn to_srgba8(&self) -> Vec<u8> {
        self.texels.iter().flat_map(|t| srgba8(*t)).collect()
    }

    /// The texels as RGBA8 (unorm, rounded, clamped to [0, 1]).
    pub fn to_rgba8(&self) -> Vec<u8> {
        self.texels
            .iter()
            .flat_map(|t| t.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect()
    }
}

/// A linear RGBA texel as sRGB RGBA8: colour through the sRGB transfer function, alpha linear,
/// each clamped to [0, 1] and rounded.
pub fn srgba8(texel: [f32; 4]) -> [u8; 4] {
    let byte = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
    let encode = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        byte(if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        })
    };
    [
        encode(texel[0]),
        encode(texel[1]),
        encode(texel[2]),
        byte(texel[3]),
    ]
}

/// A baked impostor: its layout and two atlases, each with its mip chain (level 0 first, down to
/// one texel per frame).
#[derive(Clone, Debug, PartialEq)]
pub struct ImpostorAtlas {
    /// Frames, frame size, shape, bounding sphere.
    pub layout: ImpostorLayout,
    /// Base colour (linear) and coverage in alpha; empty texels carry their nearest covered
    /// texel's colour with alpha 0.
    pub color: Vec<ImpostorImage>,
    /// Object-space normal `* 0.5 + 0.5` in rgb, the stored depth (`dot(q, dir) * 0.5 + 0.5`) in
    /// alpha; empty texels padded as in `color`.
    pub normal_depth: Vec<ImpostorImage>,
}

/// Pads every frame of `images` (which share one layout of `frames x frames` frames of
/// `frame_size` texels): each texel whose coverage (`coverage`'s alpha) is 0 takes the rgb of
/// the nearest covered texel of its own frame (4-neighbour steps, ties to the first reached),
/// and, for images other than `coverage` itself, every channel of it. Frames with no covered
/// texel are left as they are. Linear in the number of texels. Images that are not all
/// `frames x frame_size` texels a side (with that many texels) are left as they are.
pub fn dilate_frames(
    coverage: &mut ImpostorImage,
    others: &mut [&mut ImpostorImage],
    frames: u32,
    frame_size: u32,
) {
    let side = u64::from(frames) * u64::from(frame_size);
    let fits =
        |i: &ImpostorImage| u64::from(i.size) == side && i.texels.len() as u64 == side * side;
    if side == 0 || !fits(coverage) || !others.iter().all(|i| fits(i)) {
        return;
    }
    let size = coverage.size as usize;
    let fs = frame_size as usize;
    let mut source = vec![usize::MAX; size * size];
    let mut queue = std::collections::VecDeque::new();
    for fy in 0..frames as usize {
        for fx in 0..frames as usize {
            queue.clear();
            let (x0, y0) = (fx * fs, fy * fs);
            for y in y0..y0 + fs {
                for x in x0..x0 + fs {
                    let i = y * size + x;
                    if coverage.texels[i][3] > 0.0 {
                        source[i] = i;
                        queue.push_back((x, y));
                    }
                }
            }
            while let Some((x, y)) = queue.pop_front() {
                let from = source[y * size + x];
                let mut visit = |nx: usize, ny: usize| {
                    let j = ny * size + nx;
                    if source[j] == usize::MAX {
                        source[j] = from;
                        queue.push_back((nx, ny));
                    }
                };
                if x > x0 {
                    visit(x - 1, y);
                }
                if x + 1 < x0 + fs {
                    visit(x + 1, y);
                }
                if y > y0 {
                    visit(x, y - 1);
                }
                if y + 1 < y0 + fs {
                    visit(x, y + 1);
                }
            }
        }
    }
    for (i, &from) in source.iter().enumerate() {
        if from == usize::MAX || from == i {
            continue;
        }
        let c = coverage.texels[from];
        let t = &mut coverage.texels[i];
        *t = [c[0], c[1], c[2], t[3]];
        for image in others.iter_mut() {
            image.texels[i] = image.texels[from];
        }
    }
}

/// The mip chain of an atlas level of `frames x frames` frames of `frame_size` texels (a power
/// of two): `image` first, then each level the 2x2 box average of the one before, down to one
/// texel per frame, so no texel of a level straddles two frames. An image that is not
/// `frames x frame_size` texels a side, or a frame size that is not a power of two, gives the
/// image alone.
pub fn mip_chain(image: ImpostorImage, frames: u32, frame_size: u32) -> Vec<ImpostorImage> {
    let side = u64::from(frames) * u64::from(frame_size);
    let fits = u64::from(image.size) == side && image.texels.len() as u64 == side * side;
    let mut levels = vec![image];
    if !(fits && frame_size.is_power_of_two()) {
        return levels;
    }
    let mut fs = frame_size;
    while fs > 1 {
        fs /= 2;
        let prev = levels.last().expect("the chain starts with one level");
        let size = frames * fs;
        let mut next = ImpostorImage::filled(size, [0.0; 4]);
        for y in 0..size {
            for x in 0..size {
                let mut sum = [0.0f32; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let t = prev.texel(2 * x + dx, 2 * y + dy);
                    for c in 0..4 {
                        sum[c] += t[c];
                    }
                }
                next.texels[(y * size + x) as usize] = sum.map(|s| s * 0.25);
            }
        }
        levels.push(next);
    }
    levels
}

/// Scales up the alpha of every frame of every level after the first, where it falls short, so
/// that at least as large a share of its texels passes the alpha test (>= 0.5) as of the
/// frame's texels at level 0: a box filter alone averages thin covered features (leaves,
/// twigs, fences) below the test and they vanish at a distance (after Castaño's
/// coverage-preserving alpha mipmaps, which also scale down). `chain` is a [`mip_chain`] of
/// `frames x frames` frames; one that is not (sizes that do not halve down from a multiple of
/// `frames`) is left as it is. A scaled alpha is clamped to 1.
pub fn preserve_coverage(chain: &mut [ImpostorImage], frames: u32) {
    let Some(first) = chain.first() else {
        return;
    };
    if chain.len() < 2 || first.size == 0 || frames == 0 || first.size < frames {
        return;
    }
    let frames = frames as usize;
    let whole = |i: &ImpostorImage| {
        i.size as usize >= frames
            && (i.size as usize).is_multiple_of(frames)
            && i.texels.len() == (i.size as usize).pow(2)
    };
    let halving = chain
        .iter()
        .enumerate()
        .all(|(k, i)| whole(i) && Some(i.size) == first.size.checked_shr(k as u32));
    if !halving {
        return;
    }
    // The texels of frame (fx, fy) of an image.
    fn frame_texels(image: &ImpostorImage, frames: usize, fx: usize, fy: usize) -> Vec<usize> {
        let (size, fs) = (image.size as usize, image.size as usize / frames);
        (0..fs)
            .flat_map(|y| (0..fs).map(move |x| (fy * fs + y) * size + fx * fs + x))
            .collect()
    }
    let share = |image: &ImpostorImage, texels: &[usize], scale: f32| {
        let kept = texels
            .iter()
            .filter(|&&i| image.texels[i][3] * scale >= 0.5)
            .count();
        kept as f32 / texels.len().max(1) as f32
    };
    let (top, rest) = chain.split_at_mut(1);
    for fy in 0..frames {
        for fx in 0..frames {
            let want = share(&top[0], &frame_texels(&top[0], frames, fx, fy), 1.0);
            for image in rest.iter_mut() {
                let texels = frame_texels(image, frames, fx, fy);
                if share(image, &texels, 1.0) >= want {
                    continue;
                }
                // The smallest scale whose share reaches level 0's (the share grows with it).
                let (mut lo, mut hi) = (1.0f32, 2.0f32);
                while share(image, &texels, hi) < want && hi < 1e6 {
                    lo = hi;
                    hi *= 2.0;
                }
                for _ in 0..24 {
                    let mid = 0.5 * (lo + hi);
                    if share(image, &texels, mid) >= want {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                for &i in &texels {
                    image.texels[i][3] = (image.texels[i][3] * hi).min(1.0);
                }
            }
        }
    }
}

impl ImpostorAtlas {
    /// The atlas of `layout` from level 0 of each image (frames padded, as a bake leaves them
    /// and `lodkit lod --impostor` writes them): the mip chains built as a bake builds them
    /// ([`mip_chain`]; the colour's with [`preserve_coverage`]). Refuses a layout out of range
    /// or an image that is not `layout.atlas_size()` texels a side.
    pub fn from_level0(
        layout: ImpostorLayout,
        color: ImpostorImage,
        normal_depth: ImpostorImage,
    ) -> Result<Self, ImpostorError> {
        layout.validate()?;
        let expected = layout.atlas_size();
        for (atlas, image) in [("color", &color), ("normal_depth", &normal_depth)] {
            if image.size != expected || image.texels.len() != (expected as usize).pow(2) {
                return Err(ImpostorError::ImageSize {
                    atlas,
                    width: image.size,
                    height: (image.texels.len() / image.size.max(1) as usize) as u32,
                    expected,
                });
            }
        }
        let mut color = mip_chain(color, layout.frames, layout.frame_size);
        preserve_coverage(&mut color, layout.frames);
        Ok(Self {
            layout,
            color,
            normal_depth: mip_chain(normal_depth, layout.frames, layout.frame_size),
        })
    }

    /// Mip levels of each atlas: `log2(frame_size) + 1`.
    pub fn mip_levels(layout: &ImpostorLayout) -> u32 {
        layout.frame_size.max(1).ilog2() + 1
    }
}
