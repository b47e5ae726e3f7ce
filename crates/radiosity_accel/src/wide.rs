//! A sixteen-wide BVH traced one ray at a time with four-lane SIMD (SSE through glam's
//! `Vec4`): each node holds its sixteen children's boxes axis by axis in four groups of four
//! lanes, so one ray meets all of them in a few dozen vector operations, and each leaf holds
//! up to four triangles the same way, tested at once with the crate's one four-lane
//! triangle test ([`crate::lanes`]), each lane one triangle.
//!
//! The tree comes from obvhs's binary BVH (PLOC, spatial pre-splits, reinsertion), collapsed
//! to sixteen-wide nodes and leaves of at most four triangles by dynamic programming on the
//! surface-area cost ([`Plan`], after Ylitie et al. 2017).
//!
//! Why sixteen: an incoherent segment's traversal is a chain of dependent loads (node, then
//! the child it names), each missing the first-level cache, so the time goes with the number
//! of nodes visited more than with the box tests in each. Measured on the bench's rays with
//! the same collapse at each width, the speed rose from four wide to sixteen and fell again
//! beyond (twenty, twenty-four); closest hits gained as well. The collapse by cost matters
//! too: a greedy one (open the child with the largest area until the node is full) left the
//! nodes near the leaves two or three children wide and traced slower.
//!
//! Occlusion visits hit children in slot order. Measured slower at four wide: nearest-first
//! ordering, ordering by the ray's sign on the node's split axis, pushing all hit children
//! without branches; testing leaf children before descending gained nothing measurable.
//! Most segments either pass clear, visiting every box they meet anyway, or are blocked near
//! either end. At sixteen wide, boxes stored group by group (with a count of groups in use,
//! to skip empty ones) traced slower than axis by axis, and so did cache-line-aligned nodes.
//! (The figures are in `docs/PERFORMANCE.md`.)
//!
//! Boxes are widened by a millionth of the scene's extent against rounding; a segment
//! grazing a triangle almost edge-on can still come out differently from the brute-force
//! scan (one in a million on the bench's rays, where the test's hit point lay 0.05 outside
//! the triangle's own box), as between any two ray kernels.

use glam::{Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::{BvhBuildParams, bvh2::Bvh2, triangle::Triangle};

use crate::lanes::{RayLanes, TriangleLanes, hit_x4};

/// Child slot that holds nothing (its box never meets a ray).
const EMPTY: u32 = u32::MAX;
/// Child slot that holds a leaf: the low bits give its first [`Tri4`] and their count.
const LEAF: u32 = 1 << 31;
/// Traversal stack on the program stack, in entries, for trees that never need more
/// (`stack_need`; 94 for the bench's 108 k triangles). Every ray zeroes its stack, so it is
/// kept small: 1024 entries traced the bench's rays markedly slower.
const STACK: usize = 128;
/// The larger stack for trees that need more than [`STACK`]; beyond it, one on the heap.
const BIG_STACK: usize = 512;

/// Sixteen children's boxes, axis by axis in groups of four lanes, and what each child is.
#[derive(Clone, Copy, Debug)]
struct Node {
    min: [[Vec4; GROUPS]; 3],
    max: [[Vec4; GROUPS]; 3],
    /// An inner node's index, `LEAF | first << 2 | (count − 1)`, or `EMPTY`.
    child: [u32; WIDTH],
}

/// Four-lane groups of children per node (see the module notes for the measured widths).
const GROUPS: usize = 4;
/// Children per node.
const WIDTH: usize = 4 * GROUPS;

impl Node {
    /// A node whose slots are all empty: boxes that meet no ray.
    const EMPTY: Self = Self {
        min: [[Vec4::splat(f32::INFINITY); GROUPS]; 3],
        max: [[Vec4::splat(f32::NEG_INFINITY); GROUPS]; 3],
        child: [EMPTY; WIDTH],
    };
}

/// Up to four triangles, axis by axis, with edges and normal precomputed as in
/// `obvhs::rt_triangle::RtTriangle` (edges `e1 = v0 − v1`, `e2 = v2 − v0`, `ng = e1 × e2`).
///
/// Exactly three cache lines, aligned to them (192 bytes, where indices and a lane mask
/// inline made 224; the same speed, a seventh less memory): the lanes' triangle indices
/// live apart (only closest hits need them), and a lane without a triangle is all zeros,
/// whose plane distance is 0 × ∞ = NaN and so never in range. The plane test's `v0` and
/// `ng` come first.
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
struct Tri4(TriangleLanes);

/// The sixteen-wide BVH. Empty when built from no triangles.
#[derive(Clone, Debug, Default)]
pub(crate) struct WideBvh {
    nodes: Vec<Node>,
    tris: Vec<Tri4>,
    /// Each `tris` record's lanes' indices in the triangle slice the tree was built from.
    ids: Vec<[u32; 4]>,
    /// The root: an inner node's index, a leaf, or `EMPTY`.
    root: u32,
    /// Most children a traversal can hold pending at once: on the worst path from the
    /// root, each node's children but one.
    stack_need: usize,
}

/// A ray prepared for box tests (origin and inverse direction in lanes, and which side of
/// each box it enters first) and for leaf tests (origin and direction in every lane).
struct SlabRay {
    lanes: RayLanes,
    inv: [Vec4; 3],
    negative: [bool; 3],
}

impl SlabRay {
    fn new(o: Vec3A, d: Vec3A) -> Self {
        let inv = Vec3A::ONE / d;
        let splat = |v: Vec3A| [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)];
        Self {
            lanes: RayLanes { origin: splat(o), direction: splat(d) },
            inv: splat(inv),
            negative: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
        }
    }

    /// Entry distances of a node's boxes, group by group, and which of them the ray meets
    /// within `[tmin, tmax]` (bit per child).
    #[inline(always)]
    fn boxes(&self, node: &Node, tmin: f32, tmax: f32) -> ([Vec4; GROUPS], u32) {
        let mut nears = [Vec4::ZERO; GROUPS];
        let mut hits = 0;
        for (g, nears) in nears.iter_mut().enumerate() {
            let mut near = Vec4::splat(tmin);
            let mut far = Vec4::splat(tmax);
            for a in 0..3 {
                let (lo, hi) = if self.negative[a] {
                    (node.max[a][g], node.min[a][g])
                } else {
                    (node.min[a][g], node.max[a][g])
                };
                near = near.max((lo - self.lanes.origin[a]) * self.inv[a]);
                far = far.min((hi - self.lanes.origin[a]) * self.inv[a]);
            }
            *nears = near;
            hits |= near.cmple(far).bitmask() << (4 * g);
        }
        (nears, hits)
    }

    /// Distance to each triangle of `t` hit within `[tmin, tmax]`, and which lanes hit: the
    /// crate's one triangle test, each lane one triangle.
    #[inline(always)]
    fn triangles(&self, t: &Tri4, tmin: f32, tmax: f32) -> (Vec4, u32) {
        hit_x4(&self.lanes, &t.0, Vec4::splat(tmin), Vec4::splat(tmax), 0b1111)
    }
}

/// Appends the triangles under the binary node `index` to `ids`, in tree order.
fn gather(bvh2: &Bvh2, index: usize, ids: &mut Vec<u32>) {
    let node = &bvh2.nodes[index];
    if node.prim_count > 0 {
        let first = node.first_index as usize;
        ids.extend_from_slice(&bvh2.primitive_indices[first..first + node.prim_count as usize]);
    } else {
        gather(bvh2, node.first_index as usize, ids);
        gather(bvh2, node.first_index as usize + 1, ids);
    }
}

/// Cost of visiting a node (sixteen box tests), per unit of its box's half area, in the
/// collapse's surface-area cost. At sixteen wide, 0.5 to 3 (with leaves of four or eight
/// triangles) traced the bench's rays within the noise of 1.
const NODE_COST: f64 = 1.0;
/// Cost of testing one [`Tri4`], in the same units. At four wide, 0.5 to 2 (and leaves of
/// up to eight triangles, and binary trees built with one or four triangles per leaf
/// instead of obvhs's eight) all traced the bench's rays within the noise of 1 or slower.
const TRI4_COST: f64 = 1.0;
/// Most triangles in a leaf the collapse makes out of a binary subtree (one [`Tri4`]).
/// obvhs's own leaves, up to `max_prims_per_leaf`, are kept whole.
const LEAF_TRIANGLES: u32 = 4;

/// How the binary tree's nodes become wide nodes and leaves: the least surface-area
/// cost, by dynamic programming over the binary tree (Ylitie, Karras and Laine 2017,
/// "Efficient incoherent ray traversal on GPUs through compressed wide BVHs", §4.2).
///
/// A binary subtree is either one child slot of a wide node (a leaf, or an inner node
/// of its own) or spread over several slots of its parent's node; the tables hold the least
/// cost of each choice and what achieves it.
struct Plan {
    /// Per binary node: least cost of its subtree as one child slot.
    slot: Vec<f64>,
    /// Per binary node: whether that slot is a leaf (else an inner node).
    leaf: Vec<bool>,
    /// Per inner binary node, for at most 2 to `WIDTH` slots: least cost of its subtree
    /// spread over that many slots, and how many of them go to its first child.
    spread: Vec<[(f64, u8); WIDTH - 1]>,
}

impl Plan {
    fn new(bvh2: &Bvh2) -> Self {
        let n = bvh2.nodes.len();
        let mut plan = Self {
            slot: vec![0.0; n],
            leaf: vec![false; n],
            spread: vec![[(f64::INFINITY, 0); WIDTH - 1]; n],
        };
        plan.visit(bvh2, 0);
        plan
    }

    /// Least cost of `index`'s subtree over at most `slots` slots.
    fn within(&self, index: usize, slots: usize) -> f64 {
        if slots == 1 { self.slot[index] } else { self.slot[index].min(self.spread[index][slots - 2].0) }
    }

    /// Fills the tables for `index`'s subtree, children first; returns its triangle count.
    fn visit(&mut self, bvh2: &Bvh2, index: usize) -> u32 {
        let node = &bvh2.nodes[index];
        // In double precision: the areas of a scene 1e20 wide overflow a float, and an
        // infinite cost would make every choice look alike.
        let d = node.aabb.max.as_dvec3() - node.aabb.min.as_dvec3();
        let area = (d.x + d.y) * d.z + d.x * d.y;
        let leaf_cost = |count: u32| area * TRI4_COST * f64::from(count.div_ceil(4));
        if node.prim_count > 0 {
            self.slot[index] = leaf_cost(node.prim_count);
            self.leaf[index] = true;
            return node.prim_count;
        }
        let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
        let count = self.visit(bvh2, l) + self.visit(bvh2, r);
        for j in 2..=WIDTH {
            let mut best = (f64::INFINITY, 0);
            for k in 1..j {
                let cost = self.within(l, k) + self.within(r, j - k);
                if cost < best.0 {
                    best = (cost, k as u8);
                }
            }
            self.spread[index][j - 2] = best;
        }
        let inner = area * NODE_COST + self.spread[index][WIDTH - 2].0;
        let leaf = count <= LEAF_TRIANGLES && leaf_cost(count) <= inner;
        self.slot[index] = if leaf { leaf_cost(count) } else { inner };
        self.leaf[index] = leaf;
        count
    }

    /// Appends to `out` the binary nodes that fill the slots of `index`'s subtree spread
    /// over at most `slots` slots.
    fn children(&self, bvh2: &Bvh2, index: usize, slots: usize, out: &mut Vec<usize>) {
        let k = self.spread[index][slots - 2].1 as usize;
        let first = bvh2.nodes[index].first_index as usize;
        for (c, s) in [(first, k), (first + 1, slots - k)] {
            if s == 1 || self.slot[c] <= self.spread[c][s - 2].0 {
                out.push(c);
            } else {
                self.children(bvh2, c, s, out);
            }
        }
    }
}

/// The leaf's [`Tri4`] records: first index and count.
fn leaf_range(child: u32) -> std::ops::Range<usize> {
    let first = ((child & !LEAF) >> 2) as usize;
    first..first + (child & 3) as usize + 1
}

/// obvhs's binary tree over `triangles` (as its `build_bvh2_from_tris`: spatial pre-splits
/// when `params` ask, PLOC, reinsertion, leaf collapse), with every primitive's box widened by
/// its own hair, under 10⁻⁴ of its size (see [`tie_breaker`]).
///
/// Why: PLOC merges two nodes when each is the other's cheapest neighbour, and takes the
/// later of equal costs. Where costs tie exactly (a row of equal tiles, equally spaced) every
/// node picks its right neighbour, only the last pair agrees, and each pass merges one pair:
/// 50 000 tiles in a row took minutes. Widths that differ break the ties, a box that is a
/// little too large is still a bound, and the leaf test decides hits.
fn build_bvh2(triangles: &[Triangle], params: BvhBuildParams) -> Bvh2 {
    use obvhs::Boundable;
    let mut aabbs: Vec<Aabb> = triangles.iter().map(Boundable::aabb).collect();
    let mut indices: Vec<u32> = (0..triangles.len() as u32).collect();
    if params.pre_split {
        let halves = aabbs.iter().map(Aabb::half_area);
        let largest = halves.clone().fold(0.0, f32::max);
        let mean = halves.sum::<f32>() / aabbs.len().max(1) as f32;
        obvhs::splits::split_aabbs_preset(&mut aabbs, &mut indices, triangles, mean, largest);
    }
    for (k, aabb) in aabbs.iter_mut().enumerate() {
        let size = aabb.diagonal().max_element().max(f32::MIN_POSITIVE);
        aabb.max += glam::Vec3A::splat(size * tie_breaker(k as u64));
    }
    let mut bvh2 = obvhs::ploc::PlocBuilder::with_capacity(aabbs.len()).build(
        params.ploc_search_distance,
        &aabbs,
        indices,
        params.sort_precision,
        params.search_depth_threshold,
    );
    bvh2.uses_spatial_splits = params.pre_split;
    let mut reinsertion = obvhs::bvh2::reinsertion::ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh2, params.reinsertion_batch_ratio, None);
    obvhs::bvh2::leaf_collapser::collapse(
        &mut bvh2,
        params.max_prims_per_leaf.clamp(1, 255),
        params.collapse_traversal_cost,
    );
    reinsertion.run(
        &mut bvh2,
        params.reinsertion_batch_ratio * params.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    bvh2
}

/// A fraction in [10⁻⁶, 10⁻⁴) fixed by `k` (SplitMix64's finaliser): far above single
/// precision's step, so that two widened boxes' costs differ, and far below anything that
/// changes which boxes a ray meets in practice. The same for every run: trees are
/// reproducible.
fn tie_breaker(k: u64) -> f32 {
    let mut z = k.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    1e-6 + 99e-6 * ((z >> 40) as f32 / (1u64 << 24) as f32)
}

impl WideBvh {
    /// Builds the tree over `triangles` with obvhs's `params` for the binary tree.
    pub(crate) fn new(triangles: &[Triangle], params: BvhBuildParams) -> Self {
        if triangles.is_empty() {
            return Self { root: EMPTY, ..Self::default() };
        }
        let bvh2 = build_bvh2(triangles, params);
        let mut tree = Self::default();
        // Boxes are widened by a relative hair so that single-precision rounding in the slab
        // test can never drop a triangle that touches a box's face; the leaf test decides.
        let (lo, hi) =
            triangles.iter().fold((Vec3A::splat(f32::MAX), Vec3A::splat(f32::MIN)), |(lo, hi), t| {
                (lo.min(t.v0).min(t.v1).min(t.v2), hi.max(t.v0).max(t.v1).max(t.v2))
            });
        let pad = 1e-6 * lo.abs().max(hi.abs()).max_element().max(f32::MIN_POSITIVE);
        let plan = Plan::new(&bvh2);
        tree.root = tree.add(&bvh2, &plan, triangles, 0, pad);
        tree.stack_need = tree.pending(tree.root);
        tree
    }

    /// Adds the subtree of `bvh2`'s node `index` as `plan` says; returns its child slot value.
    fn add(&mut self, bvh2: &Bvh2, plan: &Plan, triangles: &[Triangle], index: usize, pad: f32) -> u32 {
        if plan.leaf[index] {
            let mut ids = Vec::new();
            gather(bvh2, index, &mut ids);
            return self.add_leaf(triangles, &ids);
        }
        let mut children = Vec::with_capacity(4);
        plan.children(bvh2, index, WIDTH, &mut children);
        let slot = self.nodes.len();
        self.nodes.push(Node::EMPTY);
        let mut node = self.nodes[slot];
        for (k, &c) in children.iter().enumerate() {
            let aabb = &bvh2.nodes[c].aabb;
            for a in 0..3 {
                node.min[a][k / 4][k % 4] = aabb.min[a] - pad;
                node.max[a][k / 4][k % 4] = aabb.max[a] + pad;
            }
            node.child[k] = self.add(bvh2, plan, triangles, c, pad);
        }
        self.nodes[slot] = node;
        slot as u32
    }

    /// Most children a traversal of `child`'s subtree holds pending at once.
    fn pending(&self, child: u32) -> usize {
        if child & LEAF != 0 {
            return 0;
        }
        let node = &self.nodes[child as usize];
        let children = node.child.iter().filter(|&&c| c != EMPTY);
        children.clone().count().saturating_sub(1) + children.map(|&c| self.pending(c)).max().unwrap_or(0)
    }

    /// Adds a leaf of the triangles `ids`.
    fn add_leaf(&mut self, triangles: &[Triangle], ids: &[u32]) -> u32 {
        let start = self.tris.len();
        for group in ids.chunks(4) {
            let zero = [Vec4::ZERO; 3];
            let mut t = TriangleLanes { v0: zero, ng: zero, e1: zero, e2: zero };
            let mut ids = [0; 4];
            for (lane, &id) in group.iter().enumerate() {
                let tri = &triangles[id as usize];
                // RtTriangle's precomputation, so the lanes compute what the one-ray test does.
                let (e1, e2) = (tri.v0 - tri.v1, tri.v2 - tri.v0);
                let ng = e1.cross(e2);
                for a in 0..3 {
                    t.v0[a][lane] = tri.v0[a];
                    t.e1[a][lane] = e1[a];
                    t.e2[a][lane] = e2[a];
                    t.ng[a][lane] = ng[a];
                }
                ids[lane] = id;
            }
            self.tris.push(Tri4(t));
            self.ids.push(ids);
        }
        let n = self.tris.len() - start;
        assert!(n <= 4 && start < 1 << 29, "BVH leaf too large or too many leaves");
        LEAF | (start as u32) << 2 | (n as u32 - 1)
    }

    /// True when some triangle crosses `origin + t · direction` for `t` in `[tmin, tmax]`.
    pub(crate) fn occluded(&self, origin: Vec3A, direction: Vec3A, tmin: f32, tmax: f32) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let ray = SlabRay::new(origin, direction);
        // The smallest stack that will do: zeroing it is part of every ray's cost.
        if self.stack_need <= STACK {
            self.occluded_with(&ray, tmin, tmax, &mut [0; STACK])
        } else if self.stack_need <= BIG_STACK {
            self.occluded_with(&ray, tmin, tmax, &mut [0; BIG_STACK])
        } else {
            self.occluded_with(&ray, tmin, tmax, &mut vec![0; self.stack_need])
        }
    }

    /// [`WideBvh::occluded`] with `stack` for the pending children, at least `stack_need` long.
    #[inline(always)]
    fn occluded_with(&self, ray: &SlabRay, tmin: f32, tmax: f32, stack: &mut [u32]) -> bool {
        let mut top = 0;
        let mut next = self.root;
        loop {
            if next & LEAF == 0 {
                let node = &self.nodes[next as usize];
                let (_, mut hits) = ray.boxes(node, tmin, tmax);
                // Children in slot order; the first goes next, the rest on the stack.
                if hits != 0 {
                    next = node.child[hits.trailing_zeros() as usize];
                    hits &= hits - 1;
                    while hits != 0 {
                        stack[top] = node.child[hits.trailing_zeros() as usize];
                        top += 1;
                        hits &= hits - 1;
                    }
                    continue;
                }
            } else {
                for t in &self.tris[leaf_range(next)] {
                    if ray.triangles(t, tmin, tmax).1 != 0 {
                        return true;
                    }
                }
            }
            if top == 0 {
                return false;
            }
            top -= 1;
            next = stack[top];
        }
    }

    /// The nearest triangle hit for `t` in `(tmin, tmax]`: its distance and index.
    pub(crate) fn closest(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, u32)> {
        if self.root == EMPTY {
            return None;
        }
        let ray = SlabRay::new(origin, direction);
        // The root's entry, then each node's children but one on the worst path.
        let need = self.stack_need + 1;
        if need <= STACK {
            self.closest_with(&ray, tmin, tmax, &mut [(0, 0.0); STACK])
        } else if need <= BIG_STACK {
            self.closest_with(&ray, tmin, tmax, &mut [(0, 0.0); BIG_STACK])
        } else {
            self.closest_with(&ray, tmin, tmax, &mut vec![(0, 0.0); need])
        }
    }

    /// [`WideBvh::closest`] with `stack` for the pending children and their entry distances,
    /// longer than `stack_need`.
    #[inline(always)]
    fn closest_with(
        &self,
        ray: &SlabRay,
        tmin: f32,
        tmax: f32,
        stack: &mut [(u32, f32)],
    ) -> Option<(f32, u32)> {
        let mut top = 0;
        let mut best: Option<(f32, u32)> = None;
        let mut limit = tmax;
        stack[0] = (self.root, tmin);
        top += 1;
        while top > 0 {
            top -= 1;
            let (child, enter) = stack[top];
            if enter > limit {
                continue;
            }
            if child & LEAF == 0 {
                let node = &self.nodes[child as usize];
                let (near, hits) = ray.boxes(node, tmin, limit);
                // Push the far children first so the nearest comes off the stack next.
                let mut order = [(0u32, 0.0f32); WIDTH];
                let mut n = 0;
                let mut bits = hits;
                while bits != 0 {
                    let k = bits.trailing_zeros() as usize;
                    order[n] = (node.child[k], near[k / 4][k % 4]);
                    n += 1;
                    bits &= bits - 1;
                }
                order[..n].sort_unstable_by(|a, b| b.1.total_cmp(&a.1));
                for entry in &order[..n] {
                    stack[top] = *entry;
                    top += 1;
                }
            } else {
                let range = leaf_range(child);
                for (t, id) in self.tris[range.clone()].iter().zip(&self.ids[range]) {
                    let (dist, mut hits) = ray.triangles(t, tmin, limit);
                    while hits != 0 {
                        let k = hits.trailing_zeros() as usize;
                        // Ties go to the lower triangle index, as a scan of the slice would.
                        let better = match best {
                            None => true,
                            Some((d, best_id)) => dist[k] < d || (dist[k] == d && id[k] < best_id),
                        };
                        if better {
                            best = Some((dist[k], id[k]));
                            limit = dist[k];
                        }
                        hits &= hits - 1;
                    }
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unused slots of a partly filled node hold boxes that meet no ray, whatever its
    /// direction.
    #[test]
    fn empty_slots_meet_no_ray() {
        let node = Node::EMPTY;
        for d in [Vec3A::X, -Vec3A::Y, Vec3A::new(1.0, -2.0, 3.0), Vec3A::new(1e-7, 1e-7, -1.0)] {
            let ray = SlabRay::new(Vec3A::ZERO, d);
            assert_eq!(ray.boxes(&node, 0.0, f32::MAX).1, 0, "{d}");
        }
    }

    /// The collapse keeps every triangle exactly once (the medium preset makes no spatial
    /// splits), leaves hold at most four triangles per record and their lanes' indices, and
    /// nodes come out well filled (each node visited is a cache miss saved or spent).
    #[test]
    fn the_collapse_keeps_every_triangle_and_fills_the_nodes() {
        let mut next = crate::test_uniforms(0x9e37_79b9_7f4a_7c15u64);
        let triangles: Vec<Triangle> = (0..5000)
            .map(|_| {
                let c = Vec3A::new(next(), next(), next()) * 10.0;
                let mut d = || Vec3A::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.5;
                Triangle { v0: c, v1: c + d(), v2: c + d() }
            })
            .collect();
        let tree = WideBvh::new(&triangles, BvhBuildParams::medium_build());
        let mut seen = vec![0u32; triangles.len()];
        let mut leaves = 0;
        let mut stack = vec![tree.root];
        while let Some(c) = stack.pop() {
            if c == EMPTY {
                continue;
            }
            if c & LEAF != 0 {
                leaves += 1;
                for (t, ids) in tree.tris[leaf_range(c)].iter().zip(&tree.ids[leaf_range(c)]) {
                    for lane in 0..4 {
                        // A live lane holds its triangle's normal; a padded one is all zeros.
                        let t = &t.0;
                        if t.ng.iter().any(|n| n[lane] != 0.0) {
                            seen[ids[lane] as usize] += 1;
                        } else {
                            assert!(t.v0.iter().chain(&t.e1).chain(&t.e2).all(|v| v[lane] == 0.0));
                        }
                    }
                }
            } else {
                stack.extend(tree.nodes[c as usize].child);
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "triangles missing or repeated");
        let children = (tree.nodes.len() - 1 + leaves) as f32 / tree.nodes.len() as f32;
        assert!(children > WIDTH as f32 / 2.0, "{children} children per node");
    }
}

#[cfg(test)]
mod more_tests {
    /// Triangles at geometrically growing distances (up to 1e31: areas beyond a float's
    /// range) make a lopsided binary tree, whose worst path holds more pending children than
    /// the small stack: traversals take the larger one, and answer as the scan does.
    #[test]
    fn a_lopsided_tree_of_huge_extent_agrees_with_brute_force() {
        let tris: Vec<[Vec3; 3]> = (0..400)
            .map(|i| {
                let (x, s) = (1.2f32.powi(i), 0.1 * 1.2f32.powi(i));
                [Vec3::new(x, 0.0, 0.0), Vec3::new(x, s, 0.0), Vec3::new(x, 0.0, s)]
            })
            .collect();
        let (bvh, brute) = (Bvh::new(&tris), BruteForce::new(&tris));
        assert!(bvh.tree.stack_need > super::STACK, "stack need {}", bvh.tree.stack_need);
        let mut blocked = 0;
        for i in (0..400).step_by(3) {
            let x = 1.2f32.powi(i);
            for y in [0.02, 0.2] {
                let (a, b) = (Vec3::new(0.5 * x, y * x, 0.02 * x), Vec3::new(1.5 * x, y * x, 0.02 * x));
                let expected = brute.occluded(a, b);
                assert_eq!(bvh.occluded(a, b), expected, "{a} -> {b}");
                blocked += usize::from(expected);
                // Closest hits only near: their barycentrics multiply areas (1e11 wide overflows).
                if x < 1e6 {
                    let (h, r) = (bvh.closest_hit(a, b - a, 1.0), brute.closest_hit(a, b - a, 1.0));
                    assert_eq!(h.map(|h| h.triangle), r.map(|h| h.triangle), "{a} -> {b}");
                }
            }
        }
        assert!(blocked > 50 && blocked < 250, "blocked {blocked}");
    }

    use crate::{BruteForce, Bvh, RayQuery};
    use glam::Vec3;

    /// Tiny and degenerate scenes: one to five triangles (partly filled leaves and nodes),
    /// a zero-area triangle and a sliver, against the brute-force scan.
    #[test]
    fn small_and_degenerate_scenes_agree_with_brute_force() {
        let base = [
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)],
            [Vec3::new(0.5, 0.5, 0.5), Vec3::new(0.5, 0.5, 0.5), Vec3::new(0.7, 0.2, 0.5)], // a point-line
            [Vec3::new(-1.0, 0.2, 0.3), Vec3::new(2.0, 0.2, 0.3), Vec3::new(2.0, 0.2 + 1e-6, 0.3)], // sliver
            [Vec3::new(0.2, -1.0, -1.0), Vec3::new(0.2, 2.0, -1.0), Vec3::new(0.2, 0.5, 2.0)],
        ];
        let mut uniform = crate::test_uniforms(0x853c_49e6_748f_ea9bu64);
        let mut next = move || uniform() * 3.0 - 1.0;
        for n in 1..=base.len() {
            let tris = &base[..n];
            let (bvh, brute) = (Bvh::new(tris), BruteForce::new(tris));
            for _ in 0..2000 {
                let a = Vec3::new(next(), next(), next());
                let b = Vec3::new(next(), next(), next());
                assert_eq!(bvh.occluded(a, b), brute.occluded(a, b), "{n} triangles: {a} -> {b}");
                let (h, r) = (bvh.closest_hit(a, b - a, 1.0), brute.closest_hit(a, b - a, 1.0));
                assert_eq!(h.map(|h| h.triangle), r.map(|h| h.triangle), "{n} triangles: {a} -> {b}");
            }
        }
    }

    /// Closest hits on a scene large enough for a deep tree (partly filled leaves, every
    /// level of the collapse) agree with the scan, triangle and distance.
    #[test]
    fn closest_hits_agree_on_a_deep_tree() {
        let mut next = crate::test_uniforms(0x2545_f491_4f6c_dd1du64);
        let tris: Vec<[Vec3; 3]> = (0..3000)
            .map(|_| {
                let c = Vec3::new(next(), next(), next()) * 10.0;
                let d = |n: &mut dyn FnMut() -> f32| Vec3::new(n() - 0.5, n() - 0.5, n() - 0.5) * 0.8;
                [c, c + d(&mut next), c + d(&mut next)]
            })
            .collect();
        let (bvh, brute) = (Bvh::new(&tris), BruteForce::new(&tris));
        let mut hits = 0;
        for _ in 0..2000 {
            let a = Vec3::new(next(), next(), next()) * 10.0;
            let d = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let (h, r) = (bvh.closest_hit(a, d, 100.0), brute.closest_hit(a, d, 100.0));
            assert_eq!(h.map(|h| h.triangle), r.map(|h| h.triangle), "{a} along {d}");
            if let (Some(h), Some(r)) = (h, r) {
                assert!((h.t - r.t).abs() <= 1e-4 * r.t.max(1.0), "{a} along {d}: {} vs {}", h.t, r.t);
                hits += 1;
            }
        }
        assert!(hits > 500, "only {hits} rays hit");
    }
}
