//! From a scene to a [`Mesh`]: every object's surfaces cut around contacts and shadow outlines,
//! latticed, graded towards inside corners, refined near other geometry and where a
//! [`Refinement`] says, two-sided objects given their back faces, then the smoothing table.

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::FxHashMap as HashMap;

use glam::DVec3;
use radiosity_core::{Material, MeshParams, Object, Polygon, Rgb, Scene, Shape, Sides};

use crate::bisection::mesh_triangles;
use crate::builder::{SurfaceBuilder, is_large, is_large_area, polygon_area_normal};
use crate::contacts::seams::cut_triangles;
use crate::contacts::{Contacts, PolygonId};
use crate::grading;
use crate::lattice::{mesh_polygon, mesh_sphere};
use crate::limits::{MAX_ELEMENTS, MeshError, estimate_polygon_elements, first_object_over_limit};
use crate::model_faces::{group_mesh_faces, group_triangles, pair_as_quad};
use crate::outline::{Outline, outline};
use crate::refinement::{Refinement, centre_key};
use crate::shadows::ShadowOutlines;
use crate::{Element, MaskedOccluder, Mesh, Patch, Smoothing, Surface};

/// Whether a surface's inside corners are needed: to grade towards them, or to leave them to
/// the grading when refining near other geometry (with the grading off too, they are left
/// ungraded).
fn grades_or_refines(params: &MeshParams) -> bool {
    params.corner_refinement > 0 || params.proximity_refinement > 0
}

/// Quarters the elements of surface `b` (facing `normal`) that other geometry comes nearer
/// to than half their size, [`MeshParams::proximity_refinement`] times (see
/// `grading::refine_near`), no smaller than the element size over 2^levels.
fn refine_near(
    b: &mut SurfaceBuilder,
    normal: DVec3,
    corners: &[(DVec3, DVec3)],
    contacts: &Contacts,
    params: &MeshParams,
) {
    let levels = params.proximity_refinement;
    if levels == 0 {
        return;
    }
    let min_size = params.element_size / f64::from(1u32 << levels);
    let near =
        |centre: DVec3, reach: f64| contacts.geometry_within(centre, normal, reach, 1e-4 * reach, corners);
    grading::refine_near(b, levels, min_size, &near);
}

/// What cuts a polygon before it is meshed.
#[derive(Clone, Copy)]
struct Cutters<'a, 'b> {
    contacts: Option<&'a Contacts<'b>>,
    shadows: Option<&'a ShadowOutlines>,
    /// The polygon's object is two-sided: what meets its back cuts it too.
    both_sides: bool,
}

impl Mesh {
    /// Meshes `scene` with `params`.
    ///
    /// # Errors
    /// [`MeshError::TooManyElements`] when the subdivision would exceed [`MAX_ELEMENTS`].
    pub fn build(scene: &Scene, params: &MeshParams) -> Result<Mesh, MeshError> {
        Self::build_refined(scene, params, &Refinement::default())
    }

    /// Meshes `scene` with `params`, then quarters the elements `refinement` names, level
    /// after level (each level names elements of the mesh the levels before it give), with
    /// the neighbours that gain a vertex on a side cut into triangles that use it.
    ///
    /// # Errors
    /// [`MeshError::TooManyElements`] when the subdivision would exceed [`MAX_ELEMENTS`].
    pub fn build_refined(
        scene: &Scene,
        params: &MeshParams,
        refinement: &Refinement,
    ) -> Result<Mesh, MeshError> {
        let too_many = |object: &str| MeshError::TooManyElements {
            object: object.chars().take(80).collect(),
            limit: MAX_ELEMENTS,
            patch_size: params.patch_size,
            element_size: params.element_size,
        };
        if let Some(i) = first_object_over_limit(scene, params) {
            return Err(too_many(&scene.objects[i].name));
        }
        let mut mesh = Mesh {
            object_names: scene.objects.iter().map(|o| o.name.clone()).collect(),
            materials: scene.materials.clone(),
            hidden_area: vec![0.0; scene.objects.len()],
            shadow_pieces: vec![0; scene.objects.len()],
            ..Mesh::default()
        };
        let contacts = (params.contacts || params.corner_refinement > 0 || params.proximity_refinement > 0)
            .then(|| Contacts::new(scene));
        let shadows = params.shadow_outlines.then(|| ShadowOutlines::new(scene)).filter(|s| !s.is_empty());
        // The back face of an emitting material that emits from its front only: the same
        // reflectance, no emission (one per material, made when first needed).
        let mut dark_back = HashMap::default();
        for (oi, o) in scene.objects.iter().enumerate() {
            let first_surface = mesh.surfaces.len() as u32;
            let two_sided = matches!(o.sides, Sides::Two { .. });
            let material = mesh.masked_material(scene, o);
            // A polygon of this object, cut around what stands on it, graded and refined.
            let cut = |mesh: &mut Mesh, p: &Polygon, id: Option<PolygonId>| {
                let cutters =
                    Cutters { contacts: contacts.as_ref(), shadows: shadows.as_ref(), both_sides: two_sided };
                mesh.mesh_cut_polygon(cutters, p, id, oi, material, params, refinement);
            };
            match &o.shape {
                Shape::Polygons(ps) => {
                    for (index, p) in ps.iter().enumerate() {
                        let v = p.vertices();
                        mesh.occluders.extend((1..v.len() - 1).map(|i| [v[0], v[i], v[i + 1]]));
                        let id = PolygonId { object: oi, index };
                        if contacts.as_ref().is_some_and(|c| c.is_pressed_flat(id, p)) {
                            mesh.hidden_area[oi] += p.area();
                            continue;
                        }
                        cut(&mut mesh, p, Some(id));
                    }
                }
                Shape::Sphere(s) => {
                    let mut b = SurfaceBuilder::default();
                    mesh_sphere(&mut b, s, params, scene.materials[o.material].is_emitter());
                    for pts in &b.patches {
                        mesh.occluders.extend((1..pts.len() - 1).map(|i| [pts[0], pts[i], pts[i + 1]]));
                    }
                    mesh.push_surface(b, oi, material, refinement);
                }
                Shape::Mesh(m) => {
                    for group in group_mesh_faces(m) {
                        let first = group[0] as usize;
                        if m.faces()[first].len() > 3 {
                            let id = PolygonId { object: oi, index: first };
                            let p = &m.polygons()[first];
                            cut(&mut mesh, p, Some(id));
                        } else if let [a, c] = group[..]
                            && let Some(quad) = pair_as_quad(m, a as usize, c as usize)
                        {
                            // Two triangles that make a convex quad (how exporters write one
                            // quad) are meshed as that quad, exactly as a quad polygon would be.
                            cut(&mut mesh, &quad, None);
                        } else {
                            // The group's outline decides its meshing, not how it was
                            // triangulated (see `outline`).
                            let outline = if group.len() > 1 { outline(m, &group) } else { None };
                            if let Some(Outline::Convex(p)) = &outline {
                                cut(&mut mesh, p, None);
                                continue;
                            }
                            let mut b = SurfaceBuilder::default();
                            // The outline's triangles, or the group's own where it has none (a
                            // lone triangle, an outline that is not plain loops).
                            let own;
                            let ts = match &outline {
                                Some(Outline::Triangles(ts)) => ts,
                                _ => {
                                    own = group_triangles(m, &group);
                                    &own
                                }
                            };
                            let normal = m.polygons()[first].normal();
                            // A large region is cut along the seams other faces make across
                            // it (see `contacts::seams`), as a convex outline's pieces are; a
                            // small one, as a lone triangle, is not, or the same faces written
                            // as one triangle and as sixteen mesh differently (the sixteen,
                            // merged into their outline, were cut along every face touching
                            // them and the one was not: Veach Bidir cut 16-fold gave 14 % more
                            // elements).
                            let area: f64 =
                                ts.iter().map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()).sum();
                            let large = is_large_area(area, params);
                            let seams = contacts
                                .as_ref()
                                .filter(|_| params.contacts && large)
                                .map(|c| c.seams(ts, normal, None, two_sided))
                                .unwrap_or_default();
                            if seams.is_empty() {
                                mesh_triangles(&mut b, ts, normal, params);
                            } else {
                                let cut = cut_triangles(ts.clone(), &seams, normal);
                                mesh_triangles(&mut b, &cut, normal, params);
                            }
                            if let Some(c) = contacts.as_ref() {
                                let edges: Vec<(DVec3, DVec3)> = if grades_or_refines(params) {
                                    group
                                        .iter()
                                        .map(|&f| (f as usize, &m.polygons()[f as usize]))
                                        .filter(|(_, p)| is_large(p, params))
                                        .flat_map(|(index, p)| {
                                            c.inside_corners(p, Some(PolygonId { object: oi, index }))
                                        })
                                        .collect()
                                } else {
                                    Vec::new()
                                };
                                grading::grade(&mut b, &edges, params.corner_refinement);
                                let normal = m.polygons()[first].normal();
                                refine_near(&mut b, normal, &edges, c, params);
                            }
                            mesh.push_surface(b, oi, material, refinement);
                        }
                    }
                    // Masks of emitting materials are not applied: a lamp is whole.
                    let own = &scene.materials[o.material];
                    let mask = own.texture.as_ref().filter(|t| t.mask.is_some() && !own.is_emitter());
                    for (f, p) in m.polygons().iter().enumerate() {
                        let v = p.vertices();
                        if let (Some(texture), Some(uv)) = (mask, m.uvs().get(f)) {
                            mesh.masked_occluders.extend((1..v.len() - 1).map(|i| MaskedOccluder {
                                occluder: (mesh.occluders.len() + i - 1) as u32,
                                uv: [uv[0], uv[i], uv[i + 1]],
                                texture: texture.clone(),
                            }));
                        }
                        mesh.occluders.extend((1..v.len() - 1).map(|i| [v[0], v[i], v[i + 1]]));
                    }
                }
            }
            if let Sides::Two { emits_back } = o.sides {
                let front_material = mesh.materials[material].clone();
                let back_material = if emits_back || !front_material.is_emitter() {
                    material as u32
                } else {
                    *dark_back.entry(material).or_insert_with(|| {
                        let name = format!("{} (back)", front_material.name);
                        mesh.materials.push(Material { name, emission: Rgb::ZERO, ..front_material });
                        (mesh.materials.len() - 1) as u32
                    })
                };
                // The back faces repeat the front's patches, elements and vertices one for one:
                // room for them at once, rather than doubling tables of millions.
                let front = &mesh.surfaces[first_surface as usize..];
                if let (Some(first), Some(last)) = (front.first(), front.last()) {
                    let patches = (last.patches.end - first.patches.start) as usize;
                    let elements = (mesh.patches[last.patches.end as usize - 1].elements.end
                        - mesh.patches[first.patches.start as usize].elements.start)
                        as usize;
                    mesh.surfaces.reserve_exact(front.len());
                    mesh.patches.reserve_exact(patches);
                    mesh.elements.reserve_exact(elements);
                }
                for s in first_surface..mesh.surfaces.len() as u32 {
                    mesh.push_back_face(s, back_material);
                }
            }
        }
        mesh.contacts_incomplete = contacts.as_ref().is_some_and(|c| c.budget_spent());
        mesh.proximity_incomplete = contacts.as_ref().is_some_and(|c| c.proximity_budget_spent());
        mesh.shrink_to_fit();
        mesh.smoothing = Smoothing::new(&mesh, params.crease_angle_deg);
        Ok(mesh)
    }

    /// Meshes polygon `p` of object `object` as one surface, or, where solids stand on it or
    /// cast shadows on it, as one surface per piece of it around their footprints (the
    /// covered area counted in [`Mesh::hidden_area`]) and shadow outlines; each surface graded
    /// and refined as `params` and `refinement` say.
    #[allow(clippy::too_many_arguments)]
    fn mesh_cut_polygon(
        &mut self,
        Cutters { contacts, shadows, both_sides }: Cutters,
        p: &Polygon,
        id: Option<PolygonId>,
        object: usize,
        material: usize,
        params: &MeshParams,
        refinement: &Refinement,
    ) {
        let large = is_large(p, params);
        let cut = contacts
            .filter(|_| large && params.contacts)
            .and_then(|c| c.cut(p, id, both_sides, |q| estimate_polygon_elements(q, params)));
        // A small face is cut only where other faces pass through it (see
        // `Contacts::small_face_cut`).
        let crossed =
            contacts.filter(|_| !large && params.contacts).and_then(|c| c.small_face_cut(p, id, both_sides));
        let pieces = match (&cut, &crossed) {
            (Some(cut), _) => {
                self.hidden_area[object] += cut.hidden;
                &cut.pieces[..]
            }
            (None, Some(crossed)) => &crossed[..],
            (None, None) => std::slice::from_ref(p),
        };
        let shadowed = shadows
            .filter(|_| large)
            .and_then(|s| s.cut(p, pieces, |q| estimate_polygon_elements(q, params)));
        if let Some(cut) = &shadowed {
            self.shadow_pieces[object] += (cut.len() - pieces.len()) as u32;
        }
        let pieces = shadowed.as_deref().unwrap_or(pieces);
        for piece in pieces {
            let mut b = SurfaceBuilder::default();
            mesh_polygon(&mut b, piece, params);
            if let Some(c) = contacts.filter(|_| large) {
                let edges = if grades_or_refines(params) { c.inside_corners(piece, id) } else { Vec::new() };
                grading::grade(&mut b, &edges, params.corner_refinement);
                refine_near(&mut b, p.normal(), &edges, c, params);
            }
            self.push_surface(b, object, material, refinement);
        }
    }

    fn push_surface(
        &mut self,
        mut b: SurfaceBuilder,
        object: usize,
        material: usize,
        refinement: &Refinement,
    ) {
        let surface = self.surfaces.len() as u32;
        for level in &refinement.levels {
            if let Some(marked) = level.get(&surface) {
                let mut splits = grading::Splits::default();
                splits.quarter_marked(&mut b, &|b, vs| marked.contains(&centre_key(b, vs)));
                splits.conform(&mut b);
            }
        }
        let vbase = self.positions.len() as u32;
        self.positions.extend(&b.positions);
        self.shading_normals.extend(&b.normals);
        let first_patch = self.patches.len() as u32;
        let mut by_patch: Vec<Vec<usize>> = vec![Vec::new(); b.patches.len()];
        for (e, (_, p)) in b.elements.iter().enumerate() {
            by_patch[*p].push(e);
        }
        for (p, corners) in b.patches.iter().enumerate() {
            let start = self.elements.len() as u32;
            let mut area = 0.0;
            for &e in &by_patch[p] {
                let local = &b.elements[e].0;
                let pts: Vec<DVec3> = local.iter().map(|&i| b.positions[i as usize]).collect();
                let (a, n, c) = polygon_area_normal(&pts);
                let mut vertices = [0u32; 4];
                for (k, &i) in local.iter().enumerate() {
                    vertices[k] = vbase + i;
                }
                area += a;
                self.elements.push(Element {
                    vertices,
                    vertex_count: local.len() as u8,
                    patch: self.patches.len() as u32,
                    centre: c,
                    normal: n,
                    area: a,
                });
            }
            let (_, n, c) = polygon_area_normal(corners);
            let mut cs = [DVec3::ZERO; 4];
            cs[..corners.len()].copy_from_slice(corners);
            self.patches.push(Patch {
                corners: cs,
                corner_count: corners.len() as u8,
                normal: n,
                centre: c,
                area,
                elements: start..self.elements.len() as u32,
                surface,
            });
        }
        self.surfaces.push(Surface {
            object: object as u32,
            material: material as u32,
            patches: first_patch..self.patches.len() as u32,
            back: false,
            twin: None,
        });
    }

    /// Gives back the tables' spare capacity: grown push by push, they hold up to twice
    /// what a million-facet model needs, for as long as the mesh lives.
    /// The material index object `o`'s surfaces take: its own, or, for a mesh whose material
    /// has an alpha mask (and does not emit), a copy whose reflectance is scaled by the share
    /// of the object's faces that is there (see `masks`), pushed onto the mesh's materials.
    fn masked_material(&mut self, scene: &Scene, o: &Object) -> usize {
        let material = &scene.materials[o.material];
        let (Shape::Mesh(m), Some(texture)) = (&o.shape, &material.texture) else { return o.material };
        if texture.mask.is_none() || material.is_emitter() || m.uvs().is_empty() {
            return o.material;
        }
        let (mut there, mut area) = (0.0, 0.0);
        for (p, uv) in m.polygons().iter().zip(m.uvs()) {
            let v = p.vertices();
            for i in 1..v.len() - 1 {
                let a = 0.5 * (v[i] - v[0]).cross(v[i + 1] - v[0]).length();
                there += a * crate::coverage(texture, &[uv[0], uv[i], uv[i + 1]]);
                area += a;
            }
        }
        let share = if area > 0.0 { there / area } else { 1.0 };
        let name = format!("{} (masked, {:.1} % there)", material.name, 100.0 * share);
        self.materials.push(Material { name, reflectance: material.reflectance * share, ..material.clone() });
        self.materials.len() - 1
    }

    fn shrink_to_fit(&mut self) {
        self.positions.shrink_to_fit();
        self.shading_normals.shrink_to_fit();
        self.elements.shrink_to_fit();
        self.patches.shrink_to_fit();
        self.surfaces.shrink_to_fit();
        self.occluders.shrink_to_fit();
        self.masked_occluders.shrink_to_fit();
    }

    /// Adds the back face of surface `s`: its vertices (normals negated), patches and elements
    /// in the same order, each wound the other way, with `material`; links the two as twins.
    fn push_back_face(&mut self, s: u32, material: u32) {
        let front = self.surfaces[s as usize].clone();
        let back = self.surfaces.len() as u32;
        let patches = front.patches.start as usize..front.patches.end as usize;
        let elements = self.patches[patches.start].elements.start as usize
            ..self.patches[patches.end - 1].elements.end as usize;
        // A surface's vertices are its own and contiguous: from its first element's lowest
        // index to the highest index any of its elements uses.
        let used = || self.elements[elements.clone()].iter().flat_map(|e| e.vertex_indices().iter().copied());
        let (vlo, vhi) = used().fold((u32::MAX, 0), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let vbase = self.positions.len() as u32;
        self.positions.extend_from_within(vlo as usize..=vhi as usize);
        for i in vlo..=vhi {
            self.shading_normals.push(-self.shading_normals[i as usize]);
        }
        let first_patch = self.patches.len() as u32;
        for p in patches {
            let mut patch = self.patches[p].clone();
            patch.corners[..patch.corner_count as usize].reverse();
            patch.normal = -patch.normal;
            patch.surface = back;
            let start = self.elements.len() as u32;
            for e in patch.elements.clone() {
                let mut el = self.elements[e as usize];
                el.vertices[..el.vertex_count as usize].reverse();
                for v in &mut el.vertices[..el.vertex_count as usize] {
                    *v = *v - vlo + vbase;
                }
                el.normal = -el.normal;
                el.patch = self.patches.len() as u32;
                self.elements.push(el);
            }
            patch.elements = start..self.elements.len() as u32;
            self.patches.push(patch);
        }
        self.surfaces.push(Surface {
            object: front.object,
            material,
            patches: first_patch..self.patches.len() as u32,
            back: true,
            twin: Some(s),
        });
        self.surfaces[s as usize].twin = Some(back);
    }
}
