//! How a [`GpuLodSelector`](super::GpuLodSelector) splits its instances into chunks, each of
//! which fits one storage binding (its instances, its states and its lists) and runs as one
//! dispatch. A device binds at most `max_storage_buffer_binding_size` bytes at a time (2^27 on
//! lavapipe: 4,194,304 instances of 32 bytes), and allocates at most `max_buffer_size` bytes per
//! buffer; past that, the instances go to several chunks, and every (group, level) list has one
//! range per chunk. Pure arithmetic, no wgpu.

use super::types::{GpuLodGroup, GpuLodInstance, SlotRange};

/// Bytes of one instance, one state and one list entry.
pub(super) const INSTANCE_BYTES: u64 = std::mem::size_of::<GpuLodInstance>() as u64;
pub(super) const STATE_BYTES: u64 = 8;
pub(super) const ENTRY_BYTES: u64 = 16;
/// Bytes of one `DrawIndexedIndirectArgs`.
pub(super) const DRAW_BYTES: u64 = 20;

/// One chunk: a run of instances, dispatched together, with its own buffers.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Chunk {
    /// Index of its first instance.
    pub first: u32,
    /// Instances in it.
    pub count: u32,
    /// Its lists, one per (group, level) slot in slot order: offsets in the chunk's entries
    /// buffer, draw offsets in the view's draws buffer.
    pub slots: Vec<SlotRange>,
    /// Bytes of its entries buffer.
    pub entry_bytes: u64,
}

/// Why the instances cannot be split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct TooSmall {
    /// Bytes one instance's share needs at the least (its instance, state and lists).
    pub needed: u64,
}

/// Splits `instances` into chunks of at most `max_count` instances (what one 2-D dispatch
/// covers) whose instances, states and lists each take at most `max` bytes (the smaller of the
/// binding and buffer limits); every list starts at a multiple of `align` bytes. `slot_count`
/// is the number of (group, level) slots of `groups`.
pub(super) fn plan(
    instances: &[GpuLodInstance],
    groups: &[GpuLodGroup],
    slot_count: u32,
    align: u64,
    (max, max_count): (u64, u64),
) -> Result<Vec<Chunk>, TooSmall> {
    let align = align.max(ENTRY_BYTES);
    let levels = |g: u32| {
        groups
            .get(g as usize)
            .map_or(0, |g| u64::from(g.level_count))
    };
    // Every list of a chunk may start up to `align - 1` bytes after the previous one ends.
    let padding = u64::from(slot_count) * align;
    let most_levels = groups.iter().map(|g| u64::from(g.level_count)).max();
    let needed = INSTANCE_BYTES.max(most_levels.unwrap_or(0) * ENTRY_BYTES + padding);
    if needed > max {
        return Err(TooSmall { needed });
    }
    let mut chunks = Vec::new();
    let mut per_group = vec![0u32; groups.len()];
    let (mut first, mut count, mut entries) = (0u32, 0u64, padding);
    for (i, inst) in instances.iter().enumerate() {
        let list_bytes = levels(inst.group) * ENTRY_BYTES;
        let full = (count + 1) * INSTANCE_BYTES > max
            || entries + list_bytes > max
            || count + 1 > max_count;
        if full {
            chunks.push(chunk(
                groups,
                &per_group,
                first,
                count as u32,
                align,
                chunks.len(),
            ));
            per_group.iter_mut().for_each(|c| *c = 0);
            (first, count, entries) = (i as u32, 0, padding);
        }
        if let Some(c) = per_group.get_mut(inst.group as usize) {
            *c += 1;
        }
        count += 1;
        entries += list_bytes;
    }
    if count > 0 || chunks.is_empty() {
        chunks.push(chunk(
            groups,
            &per_group,
            first,
            count as u32,
            align,
            chunks.len(),
        ));
    }
    // Draw offsets: chunk-major, slot by slot.
    for (c, ch) in chunks.iter_mut().enumerate() {
        for (s, slot) in ch.slots.iter_mut().enumerate() {
            slot.draw_offset = (c as u64 * u64::from(slot_count) + s as u64) * DRAW_BYTES;
        }
    }
    Ok(chunks)
}

/// One chunk's lists: every level of group g holds as many entries as g has instances here.
fn chunk(
    groups: &[GpuLodGroup],
    per_group: &[u32],
    first: u32,
    count: u32,
    align: u64,
    index: usize,
) -> Chunk {
    let mut slots = Vec::new();
    let mut entries = 0u64;
    for (g, group) in groups.iter().enumerate() {
        for _ in 0..group.level_count {
            slots.push(SlotRange {
                chunk: index as u32,
                slot: slots.len() as u32,
                draw_offset: 0,
                entries_offset: entries,
                capacity: per_group[g],
            });
            entries += (u64::from(per_group[g]) * ENTRY_BYTES).div_ceil(align) * align;
        }
    }
    Chunk {
        first,
        count,
        slots,
        entry_bytes: entries.max(ENTRY_BYTES),
    }
}

/// Invocations one 2-D dispatch of `workgroup`-wide workgroups covers with at most `max_dim`
/// workgroups per dimension.
pub(super) fn grid_capacity(workgroup: u32, max_dim: u32) -> u64 {
    u64::from(max_dim.max(1)).pow(2) * u64::from(workgroup)
}

/// The 2-D grid of 64-wide workgroups that covers `count` invocations with at most `max_dim`
/// workgroups per dimension: (x, y), x * y * 64 >= count (y <= max_dim while `count` is at most
/// [`grid_capacity`]). The shader numbers an invocation `(workgroup.y * x + workgroup.x) * 64 +
/// local` and skips those past `count`.
pub(super) fn grid(count: u32, workgroup: u32, max_dim: u32) -> (u32, u32) {
    let groups = count.div_ceil(workgroup).max(1);
    let x = groups.min(max_dim.max(1));
    (x, groups.div_ceil(x))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::select::SELECT_MAX_LEVELS;

    fn group(levels: u32, first_slot: u32) -> GpuLodGroup {
        GpuLodGroup {
            levels: [[0.0; 4]; SELECT_MAX_LEVELS],
            level_count: levels,
            max_distance: f32::MAX,
            fade_from: f32::MAX,
            hysteresis: 0.0,
            first_slot,
            pad: [0; 3],
        }
    }

    fn inst(group: u32) -> GpuLodInstance {
        GpuLodInstance::new(glam::Vec3::ZERO, 1.0, 1.0, group)
    }

    #[test]
    fn one_chunk_when_everything_fits() {
        let groups = [group(2, 0), group(3, 2)];
        let insts: Vec<_> = (0..10).map(|i| inst(i % 2)).collect();
        let chunks = plan(&insts, &groups, 5, 256, (1 << 27, u64::MAX)).unwrap();
        assert_eq!(chunks.len(), 1);
        let c = &chunks[0];
        assert_eq!((c.first, c.count), (0, 10));
        // 5 instances per group: 80 bytes per list, each list aligned to 256.
        let offsets: Vec<u64> = c.slots.iter().map(|s| s.entries_offset).collect();
        assert_eq!(offsets, [0, 256, 512, 768, 1024]);
        assert!(c.slots.iter().all(|s| s.capacity == 5));
        let draws: Vec<u64> = c.slots.iter().map(|s| s.draw_offset).collect();
        assert_eq!(draws, [0, 20, 40, 60, 80]);
    }

    #[test]
    fn chunks_split_where_a_binding_would_overflow_and_cover_every_instance() {
        // One group of 3 levels: 48 list bytes and 32 instance bytes per instance; 4 slots'
        // worth of padding (4 x 16): a binding of 1024 bytes holds (1024 - 48) / 48 = 20.
        let groups = [group(3, 0)];
        let insts: Vec<_> = (0..50).map(|_| inst(0)).collect();
        let chunks = plan(&insts, &groups, 3, 16, (1024, u64::MAX)).unwrap();
        let counts: Vec<u32> = chunks.iter().map(|c| c.count).collect();
        assert_eq!(counts, [20, 20, 10]);
        let firsts: Vec<u32> = chunks.iter().map(|c| c.first).collect();
        assert_eq!(firsts, [0, 20, 40]);
        for c in &chunks {
            assert!(u64::from(c.count) * INSTANCE_BYTES <= 1024);
            assert!(c.entry_bytes <= 1024, "{c:?}");
        }
        // Draw offsets run over (chunk, slot).
        assert_eq!(chunks[2].slots[1].draw_offset, (2 * 3 + 1) * DRAW_BYTES);
        assert_eq!(chunks[2].slots[1].chunk, 2);
    }

    #[test]
    fn instances_of_no_group_take_only_their_own_bytes() {
        let groups = [group(1, 0)];
        let insts: Vec<_> = (0..64).map(|_| inst(9)).collect();
        let chunks = plan(&insts, &groups, 1, 16, (32 * 16, u64::MAX)).unwrap();
        assert_eq!(chunks.len(), 4, "16 instances of 32 bytes per chunk");
        assert!(chunks.iter().all(|c| c.slots[0].capacity == 0));
    }

    #[test]
    fn a_binding_too_small_for_one_instance_is_an_error() {
        let groups = [group(8, 0)];
        let err = plan(&[inst(0)], &groups, 8, 256, (1024, u64::MAX)).unwrap_err();
        assert_eq!(err.needed, 8 * 16 + 8 * 256);
    }

    #[test]
    fn no_instances_is_one_empty_chunk() {
        let chunks = plan(&[], &[group(2, 0)], 2, 16, (1 << 20, u64::MAX)).unwrap();
        assert_eq!(chunks.len(), 1);
        assert_eq!(chunks[0].count, 0);
    }

    #[test]
    fn chunks_hold_no_more_than_one_dispatch_covers() {
        let groups = [group(1, 0)];
        let insts: Vec<_> = (0..2000).map(|_| inst(0)).collect();
        let cap = grid_capacity(64, 4); // 4 x 4 workgroups of 64
        let chunks = plan(&insts, &groups, 1, 16, (1 << 30, cap)).unwrap();
        let counts: Vec<u32> = chunks.iter().map(|c| c.count).collect();
        assert_eq!(counts, [1024, 976]);
        for c in &chunks {
            let (x, y) = grid(c.count, 64, 4);
            assert!(x <= 4 && y <= 4, "{x} x {y}");
        }
    }

    #[test]
    fn the_grid_covers_every_invocation_within_the_dimension_limit() {
        assert_eq!(grid(1, 64, 65535), (1, 1));
        assert_eq!(grid(64 * 65535, 64, 65535), (65535, 1));
        assert_eq!(grid(64 * 65535 + 1, 64, 65535), (65535, 2));
        assert_eq!(grid(100_000_000, 64, 65535), (65535, 24));
        // A lowered limit: 1000 invocations in workgroups of 64, at most 4 per dimension.
        let (x, y) = grid(1000, 64, 4);
        assert_eq!((x, y), (4, 4));
        assert!(x * y * 64 >= 1000);
    }
}
