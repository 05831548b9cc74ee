//! Objects that switch as a whole: the meshes under one node share their switch distances
//! (Unity's LODGroup switches an object, not its parts), each level's from the largest of their
//! own, measured in world units (a mesh's view-normalized distance times its node's world
//! scale, the unit an engine measures it in).

use std::collections::HashMap;

/// Which node a mesh switches with: [`objects`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Grouping {
    /// Each mesh by itself.
    PerMesh,
    /// The meshes under one top-level node of the scene together; under a node named here, the
    /// meshes below it (the nearest named node above a mesh's node wins).
    Nodes(Vec<String>),
    /// Every mesh of the file together: a file that is one object whose parts are top-level
    /// nodes (Khronos's FlightHelmet).
    Whole,
}

/// The object key of [`Grouping::Whole`].
const WHOLE: usize = usize::MAX;

/// A mesh's object: the node it switches with, and the world scale of the first node showing
/// it.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// The object's node (None: the mesh by itself, or shown by no node).
    pub node: Option<usize>,
    /// The object's name, for the report.
    pub name: String,
    /// Largest axis of the world scale of the first node showing the mesh (1 where none does).
    pub scale: f32,
}

/// Each mesh's [`Object`] (indexed by mesh), as `grouping` says, from the node tree of the
/// document's nodes (children lists). A node `grouping` names that the file does not have is an
/// error naming it. A mesh shown by several nodes belongs to the first one's object (the
/// others' show it with those distances).
pub fn objects(document: &gltf::Document, grouping: &Grouping) -> Result<Vec<Object>, String> {
    if let Grouping::Nodes(named) = grouping
        && let Some(missing) = named
            .iter()
            .find(|n| !document.nodes().any(|node| node.name() == Some(n.as_str())))
    {
        return Err(format!(
            "--object {missing}: the file has no node of that name"
        ));
    }
    let mut parent: HashMap<usize, usize> = HashMap::new();
    for node in document.nodes() {
        for child in node.children() {
            parent.entry(child.index()).or_insert(node.index());
        }
    }
    let name = |n: usize| {
        document
            .nodes()
            .nth(n)
            .and_then(|node| node.name().map(str::to_owned))
            .unwrap_or_else(|| format!("node {n}"))
    };
    let local_scale = |n: usize| {
        document.nodes().nth(n).map_or(1.0, |node| {
            let (_, _, s) = node.transform().decomposed();
            s.iter().fold(0.0f32, |m, x| m.max(x.abs()))
        })
    };
    // The chain from a node up to its root (a cycle, which a valid file has not, ends it).
    let chain = |mut n: usize| {
        let mut up = vec![n];
        while let Some(&p) = parent.get(&n) {
            if up.contains(&p) {
                break;
            }
            up.push(p);
            n = p;
        }
        up
    };
    Ok(document
        .meshes()
        .map(|mesh| {
            let shown = document
                .nodes()
                .find(|n| n.mesh().is_some_and(|m| m.index() == mesh.index()));
            let Some(first) = shown else {
                return Object {
                    node: None,
                    name: format!("mesh {}", mesh.index()),
                    scale: 1.0,
                };
            };
            let up = chain(first.index());
            let scale = up.iter().map(|&n| local_scale(n)).product::<f32>();
            let scale = if scale.is_finite() && scale > 0.0 {
                scale
            } else {
                1.0
            };
            let node = match grouping {
                Grouping::PerMesh => None,
                Grouping::Whole => Some(WHOLE),
                Grouping::Nodes(named) => Some(
                    up.iter()
                        .copied()
                        .find(|&n| named.contains(&name(n)))
                        .unwrap_or(*up.last().expect("the node itself")),
                ),
            };
            let label = match node {
                None => format!("mesh {}", mesh.index()),
                Some(WHOLE) => "the whole file".to_owned(),
                Some(n) => name(n),
            };
            Object {
                node,
                name: label,
                scale,
            }
        })
        .collect())
}

/// The distances each mesh switches at when its object's meshes share them: for each level,
/// the largest world distance among the object's meshes that have that level (and never less
/// than the level before: a mesh with fewer levels drops out), back in each mesh's own units.
/// `distances[m]` are mesh `m`'s view-normalized switch distances (level 0 first) and its hide
/// distance last; the result has the same shape.
pub fn shared(objects: &[Object], distances: &[Vec<f32>]) -> Vec<Vec<f32>> {
    let mut out = distances.to_vec();
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    for (m, o) in objects.iter().enumerate() {
        if let Some(node) = o.node {
            groups.entry(node).or_default().push(m);
        }
    }
    // An object of one mesh keeps its distances exactly (no round trip through world units).
    for members in groups.values().filter(|m| m.len() > 1) {
        // Each member's list: its switches, then its hide distance; shared position by
        // position for the switches, and the hide distances among themselves.
        let switches = |m: usize| &distances[m][..distances[m].len().saturating_sub(1)];
        let longest = members
            .iter()
            .map(|&m| switches(m).len())
            .max()
            .unwrap_or(0);
        let mut world = Vec::with_capacity(longest);
        for i in 0..longest {
            let d = members
                .iter()
                .filter_map(|&m| switches(m).get(i).map(|d| d * objects[m].scale))
                .fold(0.0f32, f32::max);
            let before = world.last().copied().unwrap_or(0.0);
            world.push(d.max(before));
        }
        let hide = members
            .iter()
            .filter_map(|&m| distances[m].last().map(|d| d * objects[m].scale))
            .fold(0.0f32, f32::max);
        for &m in members {
            let s = objects[m].scale;
            let n = switches(m).len();
            let last = world.get(n.saturating_sub(1)).copied().unwrap_or(0.0);
            out[m] = world[..n]
                .iter()
                .map(|d| d / s)
                .chain(std::iter::once(hide.max(last) / s))
                .collect();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn object(node: Option<usize>, scale: f32) -> Object {
        Object {
            node,
            name: String::new(),
            scale,
        }
    }

    /// Two meshes of one object take the larger world distance level by level (one at twice
    /// the scale of the other: its units are half as long); a mesh with fewer levels keeps its
    /// count and the shared distances stay in order; a mesh by itself keeps its own.
    #[test]
    fn an_objects_meshes_share_the_largest_world_distance() {
        let objects = [
            object(Some(0), 1.0),
            object(Some(0), 2.0),
            object(None, 1.0),
        ];
        let distances = vec![
            vec![0.0, 4.0, 8.0, 20.0],
            vec![0.0, 1.0, 30.0],
            vec![0.0, 3.0, 9.0],
        ];
        let out = shared(&objects, &distances);
        // World: mesh 0 switches at 4 and 8, hides at 20; mesh 1 at 2, hides at 60.
        // Shared: level 1 at max(4, 2) = 4, level 2 at 8, hidden beyond max(20, 60) = 60.
        assert_eq!(out[0], vec![0.0, 4.0, 8.0, 60.0]);
        assert_eq!(out[1], vec![0.0, 2.0, 30.0]);
        assert_eq!(out[2], distances[2], "by itself");
    }
}
