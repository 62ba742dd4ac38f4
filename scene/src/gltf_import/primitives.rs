//! Mesh primitives: reading triangle primitives once and instancing them per node.

use std::collections::hash_map::Entry;
use std::collections::{BTreeMap, HashMap};

use glam::DVec3;
use gltf::accessor::Dimensions;
use gltf::mesh::Mode;
use gltf::Semantic;
use trisort_format::{Geometry, Node, Vertex};

use super::materials::{Materials, Needs};
use super::nodes::NodeTree;
use super::tangents;
use super::{mesh_label, node_label, Importer};
use crate::SceneError;

/// Primitives that are not triangles, by kind ("points", "lines"): where they are, for one
/// note per kind.
type Skipped = BTreeMap<&'static str, Vec<String>>;

/// A primitive's normals (`None`: the file has none), its two texture coordinate sets and its
/// tangents, as [`PrimitiveData`] holds them.
type Attributes = (
    Option<Vec<[f32; 3]>>,
    [Option<Vec<[f32; 2]>>; 2],
    Option<Vec<[f32; 4]>>,
);

/// The triangles of one mesh primitive, read once and instanced per node: one vertex per
/// file vertex, or, for a primitive without normals, three vertices per triangle carrying its
/// face normal.
struct PrimitiveData {
    positions: Vec<[f32; 3]>,
    /// Unit normals (from the file, or flat).
    normals: Vec<[f32; 3]>,
    /// TEXCOORD_0 and TEXCOORD_1, where a material of the primitive samples that set and the
    /// primitive has it.
    uvs: [Option<Vec<[f32; 2]>>; 2],
    /// Tangents (file's or generated), where a material of the primitive has a normal texture.
    tangents: Option<Vec<[f32; 4]>>,
    /// Triangles in the file's winding (counter-clockwise about the local normals).
    triangles: Vec<[u32; 3]>,
    zero_area: u64,
    material: u32,
}

impl Importer<'_> {
    /// The geometry of the imported scene: every mesh instance of its nodes in node order
    /// (the triangle id order of the module documentation), with the file's nodes, materials
    /// and textures. Returns it with its number of zero-area triangles.
    pub(super) fn geometry(
        &mut self,
        file_nodes: &[gltf::Node],
        tree: &NodeTree,
        nodes: Vec<Node>,
        mut materials: Materials,
    ) -> Result<(Geometry, u64), SceneError> {
        let world = trisort_format::world_transforms(&nodes, &[]);
        let mut geometry = Geometry {
            nodes,
            ..Geometry::default()
        };
        // Each primitive is read once (`None`: skipped, noted once) and instanced per node.
        let mut primitive_cache: HashMap<(usize, usize), Option<PrimitiveData>> = HashMap::new();
        let mut skipped = Skipped::new();
        let mut zero_area_triangles = 0u64;
        for &n in &tree.order {
            let node = &file_nodes[n];
            if !tree.in_scene[n] {
                continue;
            }
            if let Some(skin) = node.skin() {
                return Err(SceneError::Skinned {
                    file: self.file.clone(),
                    node: node_label(node),
                    skin: skin.index(),
                });
            }
            let Some(mesh) = node.mesh() else { continue };
            let new_node = tree.new_index[n];
            let flip = world[new_node as usize].determinant() < 0.0;
            for prim in mesh.primitives() {
                let key = (mesh.index(), prim.index());
                if let Entry::Vacant(slot) = primitive_cache.entry(key) {
                    slot.insert(self.read_once(&mesh, &prim, &mut materials, &mut skipped)?);
                }
                let Some(Some(data)) = primitive_cache.get(&key) else {
                    continue;
                };
                zero_area_triangles += data.zero_area;
                self.sources
                    .extend((0..data.triangles.len() as u32).map(|triangle| {
                        super::TriangleSource {
                            mesh: mesh.index() as u32,
                            primitive: prim.index() as u32,
                            triangle,
                            node: n as u32,
                        }
                    }));
                instance(&mut geometry, data, new_node, flip).map_err(|problem| {
                    SceneError::Unsupported {
                        file: self.file.clone(),
                        problem,
                    }
                })?;
            }
        }
        self.note_skipped(&skipped);
        geometry.variants = materials.variant_tables(&self.variants);
        geometry.materials = materials.list;
        geometry.textures = materials.textures;
        Ok((geometry, zero_area_triangles))
    }

    /// Reads a primitive the first time a node instances it: `None` for points and lines
    /// (listed in `skipped`) and for a primitive without positions (noted).
    fn read_once(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        materials: &mut Materials,
        skipped: &mut Skipped,
    ) -> Result<Option<PrimitiveData>, SceneError> {
        let kind = match prim.mode() {
            Mode::Points => Some("points"),
            Mode::Lines | Mode::LineLoop | Mode::LineStrip => Some("lines"),
            _ => None,
        };
        if let Some(kind) = kind {
            skipped.entry(kind).or_default().push(format!(
                "{} primitive {}",
                mesh_label(mesh),
                prim.index()
            ));
            return Ok(None);
        }
        let default = materials.of(prim);
        let targets: Vec<u32> = match self.variant_maps.get(&(mesh.index(), prim.index())) {
            Some(map) => map.iter().map(|t| t.unwrap_or(default)).collect(),
            None => vec![default; self.variants.len()],
        };
        // What any material a variant may show here samples.
        let needs = (std::iter::once(default).chain(targets.iter().copied()))
            .map(|m| materials.needs[m as usize])
            .fold(Needs::default(), Needs::union);
        let material = materials.slot(default, targets);
        self.primitive(mesh, prim, material, needs)
    }

    /// One note per kind of skipped primitive, naming the first few.
    fn note_skipped(&mut self, skipped: &Skipped) {
        for (kind, list) in skipped {
            let shown: Vec<&str> = list.iter().take(4).map(String::as_str).collect();
            let more = if list.len() > shown.len() {
                ", …"
            } else {
                ""
            };
            self.notes.push(format!(
                "skipped {} {kind} primitive(s) (only triangles are drawn): {}{more}",
                list.len(),
                shown.join(", ")
            ));
        }
    }

    /// Reads one triangle primitive; `None` (with a note) when it has no positions.
    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        material: u32,
        needs: Needs,
    ) -> Result<Option<PrimitiveData>, SceneError> {
        let where_ = format!("{} primitive {}", mesh_label(mesh), prim.index());
        if prim.morph_targets().next().is_some() {
            return Err(SceneError::MorphTargets {
                file: self.file.clone(),
                mesh: mesh_label(mesh),
                primitive: prim.index(),
            });
        }
        self.decode_draco(mesh, prim)?;
        let Some(pos_acc) = prim.get(&Semantic::Positions) else {
            self.notes
                .push(format!("skipped {where_}: it has no POSITION attribute"));
            return Ok(None);
        };
        let positions = self.read_vec3(&pos_acc, &format!("{where_} POSITION"))?;
        if let Some(vertex) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(SceneError::NonFinitePosition {
                file: self.file.clone(),
                mesh: mesh_label(mesh),
                primitive: prim.index(),
                accessor: pos_acc.index(),
                vertex,
            });
        }
        let n = positions.len();
        let (normals, uvs, tangents) = self.read_attributes(prim, &where_, n, needs)?;
        let triangles = self.read_triangles(prim, &where_, n)?;
        let zero_area = triangles
            .iter()
            .filter(|t| is_zero_area(&positions, t))
            .count() as u64;
        let mut data = match normals {
            Some(normals) => PrimitiveData {
                positions,
                normals,
                uvs,
                tangents,
                triangles,
                zero_area,
                material,
            },
            None => flat(positions, uvs, tangents, &triangles, zero_area, material),
        };
        self.complete_tangents(&mut data, needs, &where_);
        Ok(Some(data))
    }

    /// The normals (where the file has them), the texture coordinate sets a material of the
    /// primitive samples and its tangents (where it has a normal texture and the file has
    /// them) of a primitive of `n` vertices; each must have `n` elements.
    fn read_attributes(
        &mut self,
        prim: &gltf::Primitive,
        where_: &str,
        n: usize,
        needs: Needs,
    ) -> Result<Attributes, SceneError> {
        let count_mismatch = |acc: &gltf::Accessor, what: &str, got: usize| SceneError::Accessor {
            file: self.file.clone(),
            accessor: acc.index(),
            usage: format!("{where_} {what}"),
            problem: format!("{got} elements, POSITION has {n}"),
        };
        let normals = match prim.get(&Semantic::Normals) {
            Some(acc) => {
                let normals = self.read_vec3(&acc, &format!("{where_} NORMAL"))?;
                if normals.len() != n {
                    return Err(count_mismatch(&acc, "NORMAL", normals.len()));
                }
                Some(normals.into_iter().map(unit).collect())
            }
            None => None,
        };
        let mut uvs = [None, None];
        for set in 0..2u32 {
            if !needs.uv[set as usize] {
                continue;
            }
            let what = format!("TEXCOORD_{set}");
            match prim.get(&Semantic::TexCoords(set)) {
                Some(acc) => {
                    let flat =
                        self.read_floats(&acc, &format!("{where_} {what}"), &[Dimensions::Vec2])?;
                    if flat.len() != 2 * n {
                        return Err(count_mismatch(&acc, &what, flat.len() / 2));
                    }
                    uvs[set as usize] = Some(flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect());
                }
                None => self.notes.push(format!(
                    "{where_} has a material sampling {what} but no {what}; it is zero"
                )),
            }
        }
        let tangents = match (needs.tangent_set, prim.get(&Semantic::Tangents)) {
            (Some(_), Some(acc)) => {
                let flat =
                    self.read_floats(&acc, &format!("{where_} TANGENT"), &[Dimensions::Vec4])?;
                if flat.len() != 4 * n {
                    return Err(count_mismatch(&acc, "TANGENT", flat.len() / 4));
                }
                Some(
                    flat.chunks_exact(4)
                        .map(|c| unit_tangent([c[0], c[1], c[2], c[3]]))
                        .collect(),
                )
            }
            _ => None,
        };
        Ok((normals, uvs, tangents))
    }

    /// The triangles of a primitive of `n` vertices: its indices (or `0..n`), each in range,
    /// grouped by its mode (a count not a multiple of 3 drops the rest, with a note).
    fn read_triangles(
        &mut self,
        prim: &gltf::Primitive,
        where_: &str,
        n: usize,
    ) -> Result<Vec<[u32; 3]>, SceneError> {
        let indices: Vec<u32> = match prim.indices() {
            Some(acc) => {
                let usage = format!("{where_} indices");
                let indices = self.read_indices(&acc, &usage)?;
                if let Some(k) = indices.iter().position(|&i| i as usize >= n) {
                    return Err(SceneError::Accessor {
                        file: self.file.clone(),
                        accessor: acc.index(),
                        usage,
                        problem: format!(
                            "index {} at position {k} is out of range ({n} vertices)",
                            indices[k]
                        ),
                    });
                }
                indices
            }
            None => (0..n as u32).collect(),
        };
        let triangles = match prim.mode() {
            Mode::Triangles => {
                let rest = indices.len() % 3;
                if rest != 0 {
                    self.notes.push(format!(
                        "{where_}: {} indices is not a multiple of 3; the last {rest} ignored",
                        indices.len(),
                    ));
                }
                indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect()
            }
            Mode::TriangleStrip => strip_triangles(&indices),
            Mode::TriangleFan => fan_triangles(&indices),
            _ => Vec::new(),
        };
        Ok(triangles)
    }

    /// Generates MikkTSpace tangents where a normal texture needs them and the file has none;
    /// without the texture coordinates it samples they stay zero, with a note.
    fn complete_tangents(&mut self, data: &mut PrimitiveData, needs: Needs, where_: &str) {
        if let (Some(set), None) = (needs.tangent_set, &data.tangents) {
            match &data.uvs[set as usize] {
                Some(uvs) => {
                    let corners =
                        tangents::generate(&data.positions, &data.normals, uvs, &data.triangles);
                    weld(data, &corners);
                }
                None => self.notes.push(format!(
                    "{where_}: its normal texture samples TEXCOORD_{set}, which it lacks, and it \
                     has no TANGENT; its tangents are zero (the normal texture has no effect)"
                )),
            }
        }
    }
}

/// Gives every vertex the tangent of its triangle corners (`corners`, 3 per triangle); where
/// the corners of one vertex got different tangents (MikkTSpace splits at mirrored or
/// discontinuous texture coordinates), the vertex is copied, one copy per tangent, and the
/// triangles use the copy of their corner. Triangle order and winding are unchanged.
fn weld(data: &mut PrimitiveData, corners: &[[f32; 4]]) {
    let n = data.positions.len();
    let mut tangents: Vec<Option<[f32; 4]>> = vec![None; n];
    let mut copies: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    for (k, t) in data.triangles.iter_mut().flatten().enumerate() {
        let tangent = corners[k];
        let v = *t as usize;
        match tangents[v] {
            None => tangents[v] = Some(tangent),
            Some(first) if first.map(f32::to_bits) == tangent.map(f32::to_bits) => {}
            Some(_) => {
                let key = (*t, tangent.map(f32::to_bits));
                *t = *copies.entry(key).or_insert_with(|| {
                    data.positions.push(data.positions[v]);
                    data.normals.push(data.normals[v]);
                    for uv in data.uvs.iter_mut().flatten() {
                        uv.push(uv[v]);
                    }
                    tangents.push(Some(tangent));
                    (tangents.len() - 1) as u32
                });
            }
        }
    }
    data.tangents = Some(
        tangents
            .into_iter()
            .map(|t| t.unwrap_or([0.0; 4]))
            .collect(),
    );
}

/// A primitive without normals as three vertices per triangle carrying the face normal (as
/// the glTF specification requires), computed in the file's winding.
fn flat(
    positions: Vec<[f32; 3]>,
    uvs: [Option<Vec<[f32; 2]>>; 2],
    tangents: Option<Vec<[f32; 4]>>,
    triangles: &[[u32; 3]],
    zero_area: u64,
    material: u32,
) -> PrimitiveData {
    let corners = || triangles.iter().flatten().map(|&i| i as usize);
    let normals = triangles
        .iter()
        .flat_map(|t| {
            let n: [f32; 3] = face_cross(&positions, t)
                .normalize_or_zero()
                .as_vec3()
                .into();
            [n; 3]
        })
        .collect();
    let uvs = uvs.map(|uv| uv.map(|uv| corners().map(|i| uv[i]).collect()));
    PrimitiveData {
        positions: corners().map(|i| positions[i]).collect(),
        normals,
        uvs,
        tangents: tangents.map(|t| corners().map(|i| t[i]).collect()),
        triangles: (0..triangles.len() as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect(),
        zero_area,
        material,
    }
}

/// A tangent as a vertex stores it (the file's or MikkTSpace's): xyz scaled to unit length, w
/// the sign of the given w (±1; glTF requires ±1); all zero (no tangent) when xyz is zero or
/// not finite.
pub(super) fn unit_tangent(t: [f32; 4]) -> [f32; 4] {
    let [x, y, z] = unit([t[0], t[1], t[2]]);
    if [x, y, z] == [0.0; 3] {
        return [0.0; 4];
    }
    [x, y, z, if t[3] < 0.0 { -1.0 } else { 1.0 }]
}

/// The normal scaled to unit length; zero when it is zero or not finite.
fn unit(n: [f32; 3]) -> [f32; 3] {
    let v = glam::Vec3::from(n);
    let len = v.length();
    if len > 0.0 && len.is_finite() {
        (v / len).into()
    } else {
        [0.0; 3]
    }
}

/// Triangles of a strip: triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}) (glTF 2.0 § 3.7.2.1).
fn strip_triangles(v: &[u32]) -> Vec<[u32; 3]> {
    (0..v.len().saturating_sub(2))
        .map(|i| [v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]])
        .collect()
}

/// Triangles of a fan: triangle i is (v_{i+1}, v_{i+2}, v_0) (glTF 2.0 § 3.7.2.1).
fn fan_triangles(v: &[u32]) -> Vec<[u32; 3]> {
    (0..v.len().saturating_sub(2))
        .map(|i| [v[i + 1], v[i + 2], v[0]])
        .collect()
}

/// Unnormalised face normal in f64: exact zero iff the triangle has zero area (the products of
/// f32 differences are exact in f64).
fn face_cross(positions: &[[f32; 3]], t: &[u32; 3]) -> DVec3 {
    let p = |i: u32| glam::Vec3::from(positions[i as usize]).as_dvec3();
    let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
    (b - a).cross(c - a)
}

/// A triangle with a repeated index or exactly zero area in local space.
fn is_zero_area(positions: &[[f32; 3]], t: &[u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || face_cross(positions, t) == DVec3::ZERO
}

/// Appends one instance of a primitive for `node`, flipping the winding when `flip`.
/// Attributes stay in the node's local space (tangents included: their handedness is that of
/// the file's winding).
fn instance(
    geometry: &mut Geometry,
    data: &PrimitiveData,
    node: u32,
    flip: bool,
) -> Result<(), String> {
    let base = geometry.vertices.len();
    if base + data.positions.len() > u32::MAX as usize {
        return Err("more than 2^32 vertices after expanding instances".to_string());
    }
    let get2 = |a: &Option<Vec<[f32; 2]>>, i: usize| a.as_ref().map_or([0.0; 2], |a| a[i]);
    geometry
        .vertices
        .extend((0..data.positions.len()).map(|i| Vertex {
            position: data.positions[i],
            normal: data.normals[i],
            uv: get2(&data.uvs[0], i),
            material: data.material,
            node,
            tangent: data.tangents.as_ref().map_or([0.0; 4], |t| t[i]),
            uv1: get2(&data.uvs[1], i),
        }));
    let order = |t: [u32; 3]| if flip { [t[0], t[2], t[1]] } else { t };
    let base = base as u32;
    geometry.triangles.extend(
        data.triangles
            .iter()
            .map(|t| order([t[0] + base, t[1] + base, t[2] + base])),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_alternate_winding_and_fans_pivot() {
        assert_eq!(
            strip_triangles(&[0, 1, 2, 3, 4]),
            vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]
        );
        assert_eq!(fan_triangles(&[0, 1, 2, 3]), vec![[1, 2, 0], [2, 3, 0]]);
        assert!(strip_triangles(&[0, 1]).is_empty());
    }
}
