//! Lit meshes out: the exported glTF/GLB reloads with the `gltf` crate with the mesh's vertex
//! count, positions, colours and radiosity; the PLY reads back; lightmaps hold the vertex
//! radiosity at chart corners.

use std::sync::Arc;

use radiosity_core::Rgb;
use radiosity_export::{
    LIGHTMAP_CELL_TEXELS, Texels, VertexColours, glb_bytes, gltf_text, lightmaps, ply_bytes, vertex_colours,
    write_lightmaps,
};
use radiosity_image::{ToneOperator, ToneParams};
use radiosity_mesh::Mesh;
use radiosity_scenes::cornell_box;
use radiosity_solver::{Problem, Solution, SolverParams};

/// The Cornell box after 150 shots: enough light everywhere for the values to be distinct.
fn solved() -> (Arc<Mesh>, Solution) {
    let scene = cornell_box();
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let params = SolverParams { max_shots: Some(150), ..SolverParams::default() };
    let mut solver = problem.solver(params).unwrap();
    solver.solve();
    (problem.mesh().clone(), solver.solution())
}

/// What a reloaded file holds, all primitives in node order.
struct Reloaded {
    positions: Vec<[f32; 3]>,
    colours: Vec<[f32; 3]>,
    radiosity: Vec<[f32; 3]>,
    indices: usize,
    names: Vec<String>,
}

/// Reads back every primitive: positions, COLOR_0, _RADIOSITY and the index count.
fn reload(bytes: &[u8]) -> Reloaded {
    let (doc, buffers, _) = gltf::import_slice(bytes).expect("the gltf crate reads our file");
    let (mut pos, mut col, mut rad, mut indices, mut names) =
        (Vec::new(), Vec::new(), Vec::new(), 0, Vec::new());
    for node in doc.nodes() {
        let mesh = node.mesh().unwrap();
        names.push(node.name().unwrap().to_owned());
        for prim in mesh.primitives() {
            assert!(prim.material().unlit(), "KHR_materials_unlit");
            let r = prim.reader(|b| Some(&buffers[b.index()]));
            pos.extend(r.read_positions().unwrap());
            col.extend(r.read_colors(0).unwrap().into_rgb_f32());
            let extra = prim.attributes().find(|(s, _)| *s == gltf::Semantic::Extras("RADIOSITY".into()));
            let (_, accessor) = extra.expect("the _RADIOSITY attribute");
            let view = accessor.view().unwrap();
            let data = &buffers[view.buffer().index()][view.offset() + accessor.offset()..];
            rad.extend((0..accessor.count()).map(|k| {
                let f = |c: usize| {
                    f32::from_le_bytes(data[k * 12 + c * 4..k * 12 + c * 4 + 4].try_into().unwrap())
                };
                [f(0), f(1), f(2)]
            }));
            indices += r.read_indices().unwrap().into_u32().count();
        }
    }
    Reloaded { positions: pos, colours: col, radiosity: rad, indices, names }
}

fn close(a: [f32; 3], b: Rgb, rel: f64) -> bool {
    a.iter().zip(b.to_array()).all(|(x, y)| (*x as f64 - y).abs() <= rel * y.abs().max(1e-6))
}

#[test]
fn glb_and_gltf_reload_with_the_same_vertices_and_colours() {
    let (mesh, solution) = solved();
    let triangles = mesh.element_triangles().count();
    let tone = ToneParams::new(1.5, ToneOperator::Aces);
    for (mode, bytes) in [
        (
            VertexColours::Linear { exposure_ev: 2.0 },
            glb_bytes(&mesh, &solution, VertexColours::Linear { exposure_ev: 2.0 }, &[]),
        ),
        (
            VertexColours::Display(tone),
            gltf_text(&mesh, &solution, VertexColours::Display(tone), &[]).into_bytes(),
        ),
    ] {
        let Reloaded { positions: pos, colours: col, radiosity: rad, indices, names } = reload(&bytes);
        assert_eq!(pos.len(), mesh.positions.len(), "same vertex count");
        assert_eq!(indices, 3 * triangles);
        assert_eq!(names, mesh.object_names);
        // The exporter lists each object's vertices in the order its triangles first use them;
        // match them back through the positions, which are distinct within an object here.
        let expected = vertex_colours(&solution, mode);
        let mut seen = 0;
        for (object, name) in mesh.object_names.iter().enumerate() {
            let mut order = Vec::new();
            for (e, tri) in mesh.element_triangles() {
                if mesh.element_object(e as usize) == object {
                    for v in tri {
                        if !order.contains(&v) {
                            order.push(v);
                        }
                    }
                }
            }
            for (k, &v) in order.iter().enumerate() {
                let i = seen + k;
                let p = mesh.positions[v as usize].as_vec3().to_array();
                assert_eq!(pos[i], p, "{name}: vertex {k}");
                assert!(
                    close(col[i], expected[v as usize], 1e-6),
                    "{name}: colour {:?} vs {:?}",
                    col[i],
                    expected[v as usize]
                );
                assert!(col[i].iter().all(|c| (0.0..=1.0).contains(c)), "glTF colours are in [0, 1]");
                assert!(close(rad[i], solution.vertex_radiosity[v as usize], 1e-6), "{name}: radiosity");
            }
            seen += order.len();
        }
        assert_eq!(seen, pos.len());
    }
}

#[test]
fn ply_holds_display_colours_and_radiosity() {
    let (mesh, solution) = solved();
    let tone = ToneParams::new(0.0, ToneOperator::Linear);
    let bytes = ply_bytes(&mesh, &solution, tone, radiosity_core::UpAxis::Y);
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(header.starts_with("ply\nformat binary_little_endian 1.0\n"));
    assert!(header.contains(&format!("element vertex {}\n", mesh.positions.len())));
    // A quad element is two triangles, a triangle element one: the Cornell box has both.
    let triangles: usize = mesh.elements.iter().map(|e| e.vertex_count as usize - 2).sum();
    assert!(triangles > mesh.elements.len(), "the box has quad elements");
    assert!(header.contains(&format!("element face {triangles}\n")), "{header}");
    // 3 floats, 3 bytes, 3 floats per vertex; then each face: a count byte and its indices.
    let vertex_size = 12 + 3 + 12;
    let faces_at = end + vertex_size * mesh.positions.len();
    assert_eq!(bytes.len(), faces_at + triangles * (1 + 3 * 4));
    // Every face has 3 indices, and the faces are the elements' triangles, in order.
    let expected: Vec<[u32; 3]> = mesh.element_triangles().map(|(_, t)| t).collect();
    let mut area = 0.0;
    for (face, want) in bytes[faces_at..].chunks_exact(13).zip(&expected) {
        assert_eq!(face[0], 3, "a face that is not a triangle");
        let index = |k: usize| u32::from_le_bytes(face[1 + 4 * k..5 + 4 * k].try_into().unwrap());
        assert_eq!([index(0), index(1), index(2)], *want);
        let [a, b, c] = want.map(|i| mesh.positions[i as usize]);
        area += 0.5 * (b - a).cross(c - a).length();
    }
    // The two halves of each quad cover it: the faces' area is the elements' area.
    assert!((area - mesh.total_area()).abs() < 1e-9 * mesh.total_area(), "{area} vs {}", mesh.total_area());
    let shown = vertex_colours(&solution, VertexColours::Display(tone));
    for v in [0, mesh.positions.len() / 2, mesh.positions.len() - 1] {
        let at = end + v * vertex_size;
        let f = |o: usize| f32::from_le_bytes(bytes[at + o..at + o + 4].try_into().unwrap());
        assert_eq!([f(0), f(4), f(8)], mesh.positions[v].as_vec3().to_array());
        assert_eq!(&bytes[at + 12..at + 15], &radiosity_core::encode_srgb(shown[v]));
        assert!(close([f(15), f(19), f(23)], solution.vertex_radiosity[v], 1e-6));
    }
}

#[test]
fn lightmaps_hold_vertex_radiosity_at_chart_corners() {
    let (mesh, solution) = solved();
    let maps = lightmaps(&mesh, &solution);
    assert_eq!(maps.len(), mesh.object_names.len());
    let charted: usize = maps.iter().map(|m| m.charts.len()).sum();
    assert_eq!(charted, mesh.elements.len(), "every element has a chart");
    for map in &maps {
        let (w, h) = (map.image.width() as f64, map.image.height() as f64);
        for (e, uvs) in &map.charts {
            for (&v, uv) in mesh.elements[*e].vertex_indices().iter().zip(uvs) {
                // A corner's uv is the centre of a texel holding that vertex's radiosity.
                let (x, y) = ((uv[0] * w - 0.5).round() as u32, (uv[1] * h - 0.5).round() as u32);
                let texel = map.image.pixel(x, y);
                assert!((texel - solution.vertex_radiosity[v as usize]).max_channel().abs() < 1e-9);
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let written =
        write_lightmaps(dir.path(), &mesh, &solution, Texels::Interpolated, radiosity_core::UpAxis::Y)
            .unwrap();
    assert_eq!(written.len(), mesh.object_names.len() + 2);
    let floor = radiosity_image::read_exr(&dir.path().join("floor.exr")).unwrap();
    assert_eq!(floor.width(), maps[0].image.width());
    assert_eq!(floor.width() % LIGHTMAP_CELL_TEXELS, 0);
    // The OBJ maps every element corner to a texture coordinate.
    let (models, materials) =
        tobj::load_obj(dir.path().join("lightmapped.obj"), &tobj::LoadOptions::default()).unwrap();
    assert_eq!(models.len(), mesh.object_names.len());
    assert_eq!(materials.unwrap()[0].diffuse_texture.as_deref(), Some("floor.exr"));
    let corners: usize = mesh.elements.iter().map(|e| e.vertex_count as usize).sum();
    assert_eq!(models.iter().map(|m| m.mesh.texcoords.len() / 2).sum::<usize>(), corners);
}

/// Gathered lightmaps of the furnace (B = E/(1 − ρ) everywhere) hold its radiosity in every
/// texel: the gather's direct part (shadow rays) plus the solution's indirect part add up
/// without counting the direct light twice. Each texel's 16 samples of 2 + 2 rays leave a few
/// % of noise: each texel within 10 %, the mean within 1 %.
#[test]
fn gathered_lightmaps_of_the_furnace_hold_its_radiosity() {
    use radiosity_image::{Gather, RenderParams, Renderer};
    let (rho, emission) = (0.5, 1.0);
    let scene = radiosity_scenes::furnace_box(rho, emission);
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mut solver = problem.solver(SolverParams::default()).unwrap();
    solver.solve();
    let solution = solver.solution();
    let mesh = problem.mesh();
    let renderer = Renderer::new(mesh.clone());
    let params = RenderParams { gather: Gather::Direct, ..RenderParams::default() };
    let maps = radiosity_export::lightmaps_with(
        mesh,
        &solution,
        Texels::Gathered { renderer: &renderer, params: &params },
    )
    .unwrap();
    let expected = emission / (1.0 - rho);
    let (mut sum, mut count) = (0.0, 0usize);
    let k = LIGHTMAP_CELL_TEXELS;
    for map in &maps {
        // The cells in use (an atlas's last row may have empty cells).
        let columns = map.image.width() / k;
        for n in 0..map.charts.len() as u32 {
            for texel in 0..k * k {
                let (x, y) = ((n % columns) * k + texel % k, (n / columns) * k + texel / k);
                let b = map.image.pixel(x, y).sum() / 3.0;
                assert!((b / expected - 1.0).abs() < 0.10, "texel ({x}, {y}): {b}, expected {expected}");
                sum += b;
                count += 1;
            }
        }
    }
    let mean = sum / count as f64;
    assert!((mean / expected - 1.0).abs() < 0.01, "mean texel {mean}, expected {expected}");
}
