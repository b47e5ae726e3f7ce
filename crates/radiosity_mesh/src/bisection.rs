//! Triangles cut by longest-edge bisection: pieces that follow a triangle's area and length,
//! for a model's triangles, a scene file's triangles and the triangulations of outlines.

use glam::DVec3;
use radiosity_core::MeshParams;

use crate::builder::SurfaceBuilder;
use crate::planar::lexicographic;

/// Meshes coplanar triangles into `b`: each triangle cut by longest-edge
/// bisection (Rivara 1984) into patches whose longest edge is at most `√2 · patch_size`, each
/// patch cut the same way into elements of at most `√2 · element_size`: the diagonal of a
/// square of the size, so a right triangle of legs `size` is one piece.
///
/// Why bisection and not a lattice: a barycentric lattice cuts every edge of a triangle into
/// the same number of steps, set by the longest edge, so a sliver (a wall's triangulation
/// around a window, the strips of a folded curtain) of 2 m by 2 cm became 81 elements of
/// 5 cm², and its whole coplanar group took the same count; bisection cuts where the
/// triangle is long, so the pieces follow the area (about `2 A / size²`, and `L / size` for
/// a sliver of length `L`).
///
/// Why the pieces fit together: an edge is cut only while it is longer than the limit (it is
/// then the longest edge of some piece, or a piece would be left too long) and always at its
/// midpoint, computed as `(a + c) / 2`, which is the same bits from either end. So how an
/// edge is cut depends on its two ends alone, and the two triangles that share it cut it at
/// the same points: the surface has no T-junctions, and its vertices merge exactly.
///
/// The triangles must share their edges' corners exactly (a group's own, or a triangulation
/// of its outline), all facing `normal`.
pub(crate) fn mesh_triangles(
    b: &mut SurfaceBuilder,
    triangles: &[[DVec3; 3]],
    normal: DVec3,
    params: &MeshParams,
) {
    let (patch_limit, element_limit) =
        (params.patch_size * std::f64::consts::SQRT_2, params.element_size * std::f64::consts::SQRT_2);
    for &t in triangles {
        // Started from its least corner, a triangle is cut into the same pieces in the same
        // order however its corners were listed (a scene file's, an OBJ's and a glTF's copy of
        // one triangle alike), so the seeded rays that reach them are the same too.
        let first = (0..3).fold(0, |m, k| if lexicographic(t[k], t[m]).is_lt() { k } else { m });
        let t = [t[first], t[(first + 1) % 3], t[(first + 2) % 3]];
        bisect(t, patch_limit, &mut |patch| {
            let label = b.patches.len();
            b.patches.push(patch.to_vec());
            bisect(patch, element_limit, &mut |e| {
                let v = e.map(|p| b.vertex(p, normal)).to_vec();
                b.elements.push((v, label));
            });
        });
    }
}

/// Hands `out` the pieces of triangle `t` (counter-clockwise) cut by longest-edge bisection
/// until no edge is longer than `limit`, each counter-clockwise like `t`.
fn bisect(t: [DVec3; 3], limit: f64, out: &mut dyn FnMut([DVec3; 3])) {
    let lengths = [t[0].distance(t[1]), t[1].distance(t[2]), t[2].distance(t[0])];
    let k = (0..3).fold(0, |best, k| if lengths[k] > lengths[best] { k } else { best });
    // A length that is not finite (coordinates past the loaders' bounds) ends the cut
    // instead of halving for ever.
    if lengths[k] <= limit || !lengths[k].is_finite() {
        out(t);
        return;
    }
    let (a, c, o) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
    let mid = (a + c) * 0.5;
    bisect([a, mid, o], limit, out);
    bisect([mid, c, o], limit, out);
}
