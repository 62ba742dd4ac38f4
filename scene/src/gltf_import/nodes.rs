//! The node hierarchy: parents, the parents-first order of the module documentation, which
//! nodes belong to the imported scene, and rest transforms.

use glam::{DMat4, DQuat, DVec3};
use trisort_format::Node;

use super::{label, node_label, Importer};
use crate::SceneError;

/// Where the file's nodes go: their new order and which of them the imported scene holds.
pub(super) struct NodeTree {
    /// The file index of every new node, in the new (parents-first) order.
    pub(super) order: Vec<usize>,
    /// The new index of every file node.
    pub(super) new_index: Vec<u32>,
    /// Whether a file node belongs to the imported scene.
    pub(super) in_scene: Vec<bool>,
}

impl Importer<'_> {
    /// Orders all nodes of the file parents first (see the module documentation), marks those
    /// of the imported scene and converts them; notes which scene is imported.
    pub(super) fn node_tree(
        &mut self,
        file_nodes: &[gltf::Node],
    ) -> Result<(NodeTree, Vec<Node>), SceneError> {
        let parent = self.parents()?;
        let listed = self.scene_roots();
        let (order, new_index) = self.depth_first_order(file_nodes, &parent, &listed)?;
        let mut in_scene = vec![false; file_nodes.len()];
        for &n in &listed {
            in_scene[n] = true;
        }
        for &n in &order {
            if let Some(p) = parent[n] {
                in_scene[n] |= in_scene[p];
            }
        }

        let mut nodes = Vec::with_capacity(order.len());
        for &n in &order {
            let node = &file_nodes[n];
            nodes.push(Node {
                name: node.name().unwrap_or("").to_string(),
                parent: parent[n].map(|p| new_index[p]),
                rest: self.rest_matrix(node)?.to_cols_array(),
            });
        }
        let tree = NodeTree {
            order,
            new_index,
            in_scene,
        };
        Ok((tree, nodes))
    }

    /// The root nodes of the imported scene (the default scene, else the first); notes when the
    /// file has several scenes or none.
    fn scene_roots(&mut self) -> Vec<usize> {
        let doc = self.doc;
        let scene = doc.default_scene().or_else(|| doc.scenes().next());
        if doc.scenes().len() > 1 {
            if let Some(s) = &scene {
                self.notes.push(format!(
                    "the file has {} scenes; imported {}",
                    doc.scenes().len(),
                    label("scene", s.index(), s.name())
                ));
            }
        }
        let listed: Vec<usize> = scene
            .as_ref()
            .map(|s| s.nodes().map(|n| n.index()).collect())
            .unwrap_or_default();
        if scene.is_none() {
            self.notes
                .push("the file has no scene: no geometry imported".to_string());
        }
        listed
    }

    /// Depth-first pre-order from the scene's roots, then the other roots: the file index of
    /// every new node, and the new index of every file node. A node that no root reaches is on
    /// a cycle: an error.
    fn depth_first_order(
        &self,
        file_nodes: &[gltf::Node],
        parent: &[Option<usize>],
        listed: &[usize],
    ) -> Result<(Vec<usize>, Vec<u32>), SceneError> {
        let mut order: Vec<usize> = Vec::with_capacity(file_nodes.len());
        let mut new_index = vec![u32::MAX; file_nodes.len()];
        let roots = listed
            .iter()
            .copied()
            .filter(|&n| parent[n].is_none())
            .chain((0..file_nodes.len()).filter(|&n| parent[n].is_none()));
        for root in roots {
            if new_index[root] != u32::MAX {
                continue;
            }
            let mut stack = vec![root];
            while let Some(n) = stack.pop() {
                new_index[n] = order.len() as u32;
                order.push(n);
                let children: Vec<usize> = file_nodes[n].children().map(|c| c.index()).collect();
                stack.extend(children.into_iter().rev());
            }
        }
        if let Some(n) = (0..file_nodes.len()).find(|&n| new_index[n] == u32::MAX) {
            return Err(self.malformed(format!(
                "{} cannot be reached from any root: the node hierarchy has a cycle",
                node_label(&file_nodes[n])
            )));
        }
        Ok((order, new_index))
    }

    /// Parents of every node, rejecting nodes with two parents.
    fn parents(&self) -> Result<Vec<Option<usize>>, SceneError> {
        let mut parent = vec![None; self.doc.nodes().len()];
        for node in self.doc.nodes() {
            for child in node.children() {
                if let Some(other) = parent[child.index()] {
                    return Err(self.malformed(format!(
                        "{} is a child of both node {other} and node {} (nodes must form trees)",
                        node_label(&child),
                        node.index()
                    )));
                }
                parent[child.index()] = Some(node.index());
            }
        }
        Ok(parent)
    }

    /// A node's local rest transform in f64.
    fn rest_matrix(&self, node: &gltf::Node) -> Result<DMat4, SceneError> {
        let m = match node.transform() {
            gltf::scene::Transform::Matrix { matrix } => {
                DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
            }
            gltf::scene::Transform::Decomposed {
                translation,
                rotation,
                scale,
            } => {
                let q = DQuat::from_array(rotation.map(f64::from));
                if q.length().is_nan() || q.length() <= 0.0 {
                    return Err(self.malformed(format!(
                        "{} has an invalid rotation {rotation:?}",
                        node_label(node)
                    )));
                }
                DMat4::from_scale_rotation_translation(
                    DVec3::from_array(scale.map(f64::from)),
                    q.normalize(),
                    DVec3::from_array(translation.map(f64::from)),
                )
            }
        };
        if !m.is_finite() {
            return Err(self.malformed(format!("{} has a non-finite transform", node_label(node))));
        }
        Ok(m)
    }
}
