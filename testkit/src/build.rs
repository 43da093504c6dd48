//! The build driver: a scene built into a BSP tree and checked.

#[allow(unused_imports)]
use super::*;

/// An input scene for [`BuildInput`].
#[derive(Clone, PartialEq, Eq)]
pub enum Scene {
    /// An open polygon soup: each entry is one polygon's vertices (invalid
    /// ones are left out of the tree; the tag is the index).
    Soup(Vec<Vec<GridPoint>>),
    /// A closed box, whose membership is known exactly.
    Box(BoxSolid),
}

impl Debug for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scene::Soup(p) => f
                .debug_tuple("Scene::Soup")
                .field(&NestedVecLit(p))
                .finish(),
            Scene::Box(b) => f.debug_tuple("Scene::Box").field(b).finish(),
        }
    }
}

/// The box `lo <= p <= hi`, its faces optionally subdivided at `splits`
/// and triangulated, mapped to the grid by an integer shear (and mirror)
/// plus `offset`: world point `q = mirror(shears(p)) + offset`.
///
/// The map has an integer inverse, so membership of a probe is decided
/// exactly in box coordinates, independently of any plane.
#[derive(Clone, PartialEq, Eq)]
pub struct BoxSolid {
    /// Lower corner (box coordinates).
    pub lo: [i32; 3],
    /// Upper corner; `lo < hi` on every axis.
    pub hi: [i32; 3],
    /// Per axis, a coordinate at which the faces along that axis are
    /// subdivided (ignored unless strictly between `lo` and `hi`).
    pub splits: [i32; 3],
    /// Bit `f` (face `f = 2 axis + (0 low, 1 high)`) splits that face's
    /// quads into triangles; bit 6 picks the diagonal.
    pub triangulate: u8,
    /// Elementary shears `(i, j, s)`: `p[i] += s p[j]`, applied in order
    /// (skipped when `i == j`).
    pub shears: [(usize, usize, i32); 3],
    /// Negate x after the shears (faces are then reversed).
    pub mirror: bool,
    /// Translation.
    pub offset: [i32; 3],
    /// Probe points, box coordinates.
    pub probes: Vec<[i32; 3]>,
    /// Rational probe points `num / den` (box coordinates), built as the
    /// intersection of three planes so they are implicit points.
    pub rational_probes: Vec<([i64; 3], i64)>,
}

impl Debug for BoxSolid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("BoxSolid")
            .field("lo", &self.lo)
            .field("hi", &self.hi)
            .field("splits", &self.splits)
            .field("triangulate", &self.triangulate)
            .field("shears", &self.shears)
            .field("mirror", &self.mirror)
            .field("offset", &self.offset)
            .field("probes", &VecLit(&self.probes))
            .field("rational_probes", &VecLit(&self.rational_probes))
            .finish()
    }
}

/// A scene, build options, viewpoints.
#[derive(Clone, PartialEq, Eq)]
pub struct BuildInput {
    /// The polygons.
    pub scene: Scene,
    /// [`BuildOptions::candidates`].
    pub candidates: usize,
    /// [`BuildOptions::sample`].
    pub sample: usize,
    /// [`BuildOptions::split_weight`].
    pub split_weight: u32,
    /// [`BuildOptions::seed`].
    pub seed: u64,
    /// Viewpoints for the traversals (out-of-range ones are skipped).
    pub eyes: Vec<[i64; 3]>,
}

impl Debug for BuildInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("BuildInput")
            .field("scene", &self.scene)
            .field("candidates", &self.candidates)
            .field("sample", &self.sample)
            .field("split_weight", &self.split_weight)
            .field("seed", &self.seed)
            .field("eyes", &VecLit(&self.eyes))
            .finish()
    }
}

/// What a [`BuildInput::check`] exercised.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Valid input polygons.
    pub polygons: usize,
    /// Fragments in the tree.
    pub fragments: usize,
    /// Inner nodes.
    pub nodes: usize,
    /// Traversals checked (eyes × orders).
    pub traversals: usize,
    /// Membership probes checked, by expected answer: inside, outside,
    /// boundary.
    pub membership: [usize; 3],
    /// Of those, implicit (rational) probes.
    pub implicit_probes: usize,
}

impl BuildInput {
    /// Decodes bytes (any bytes) into an input.
    ///
    /// ```
    /// use bsp_testkit::{BuildInput, Scene};
    /// assert!(matches!(BuildInput::decode(&[]).scene, Scene::Box(_)));
    /// ```
    pub fn decode(data: &[u8]) -> BuildInput {
        let mut b = Bytes { data };
        let kind = b.u8();
        let candidates = 1 + b.below(16);
        let sample = 1 + b.below(64);
        let split_weight = (b.u8() % 9) as u32;
        let seed = b.u64();
        let scene = if kind.is_multiple_of(4) {
            Scene::Box(decode_box(&mut b))
        } else {
            Scene::Soup(decode_soup(&mut b))
        };
        let verts: Vec<GridPoint> = match &scene {
            Scene::Soup(s) => s.iter().flatten().copied().collect(),
            Scene::Box(bx) => bx.world_corners().unwrap_or_default(),
        };
        let n = 1 + b.below(3);
        let eyes = (0..n)
            .map(|_| match b.u8() % 4 {
                1 => {
                    let v = MAX_VIEW_COORD as u64;
                    [0, 1, 2].map(|_| (b.u64() % (2 * v + 1)) as i64 - MAX_VIEW_COORD)
                }
                2 if !verts.is_empty() => verts[b.below(verts.len())].map(|c| c as i64),
                _ => [b.coord(), b.coord(), b.coord()].map(|c| c as i64),
            })
            .collect();
        BuildInput {
            scene,
            candidates,
            sample,
            split_weight,
            seed,
            eyes,
        }
    }

    /// Bytes that [`BuildInput::decode`] turns back into `self`, within
    /// the decoder's ranges (at most 12 polygons of 3 to 5 vertices or a
    /// box with at most 8 + 4 probes; `candidates` 1..=16, `sample`
    /// 1..=64, `split_weight` 0..=8, shears within -8..=8, offsets within
    /// ±2^24, 1 to 3 eyes).
    ///
    /// ```
    /// use bsp_testkit::{BuildInput, Scene};
    /// let i = BuildInput {
    ///     scene: Scene::Soup(vec![vec![[0, 0, 0], [4, 0, 0], [0, 4, 0]]]),
    ///     candidates: 8, sample: 48, split_weight: 4, seed: 1,
    ///     eyes: vec![[1, 1, 1]],
    /// };
    /// assert_eq!(BuildInput::decode(&i.encode()), i);
    /// ```
    pub fn encode(&self) -> Vec<u8> {
        let mut out = vec![
            if matches!(self.scene, Scene::Box(_)) {
                0
            } else {
                1
            },
            (self.candidates.clamp(1, 16) - 1) as u8,
            (self.sample.clamp(1, 64) - 1) as u8,
            self.split_weight.min(8) as u8,
        ];
        out.extend(self.seed.to_le_bytes());
        match &self.scene {
            Scene::Soup(polys) => {
                out.push(0); // empty pool
                out.push((polys.len().clamp(1, 12) - 1) as u8);
                for p in polys {
                    out.push(0);
                    out.push((p.len().clamp(3, 5) - 3) as u8);
                    for v in p {
                        enc_point(&mut out, *v);
                    }
                }
            }
            Scene::Box(bx) => {
                for k in 0..3 {
                    let c = |out: &mut Vec<u8>, v: i32| {
                        out.push(5);
                        out.extend(((v as i64 + M) as u32).to_le_bytes());
                    };
                    c(&mut out, bx.lo[k]);
                    c(&mut out, bx.hi[k]);
                    c(&mut out, bx.splits[k]);
                }
                out.push(bx.triangulate);
                for (i, j, s) in bx.shears {
                    out.extend([i as u8, j as u8, s as i8 as u8]);
                }
                out.push(u8::from(bx.mirror));
                for c in bx.offset {
                    out.push(2);
                    out.extend(((c as i64 + (1 << 24)) as u32).to_le_bytes());
                }
                out.push(bx.probes.len().min(8) as u8);
                for p in &bx.probes {
                    for c in p {
                        out.push(7);
                        out.push(5);
                        out.extend(((*c as i64 + M) as u32).to_le_bytes());
                    }
                }
                out.push(bx.rational_probes.len().min(4) as u8);
                for (num, den) in &bx.rational_probes {
                    out.push(4);
                    out.extend(((den - 1) as u32).to_le_bytes());
                    for c in num {
                        out.extend([0, 4]);
                        out.extend(c.to_le_bytes());
                    }
                }
            }
        }
        out.push((self.eyes.len().clamp(1, 3) - 1) as u8);
        for e in &self.eyes {
            out.push(1);
            for c in e {
                out.extend(((c + MAX_VIEW_COORD) as u64).to_le_bytes());
            }
        }
        out
    }

    /// Builds the tree and checks it exactly:
    ///
    /// - [`BspTree::sanity_check`], and the statistics agree with the
    ///   nodes;
    /// - every fragment lies inside the input polygon of its tag, the
    ///   fragments of a polygon add up to its area, and every valid input
    ///   polygon has a fragment;
    /// - from every eye, in both orders, [`BspTree::traverse`] visits every
    ///   fragment exactly once, [`BspTree::traverse_recursive`] and
    ///   [`FlatBsp::traverse`] give the same sequence, and every pair of
    ///   fragments in different nodes is separated by the plane where their
    ///   paths part, with the eye on the side drawn last (back to front) or
    ///   first (front to back);
    /// - for a box, [`BspTree::classify_point`] of every probe, grid or
    ///   implicit, agrees with exact membership computed in box
    ///   coordinates.
    pub fn check(&self) -> BuildReport {
        let mut report = BuildReport::default();
        let opts = BuildOptions::default()
            .with_candidates(self.candidates)
            .with_sample(self.sample)
            .with_split_weight(self.split_weight)
            .with_seed(self.seed);
        let faces: Vec<Vec<GridPoint>> = match &self.scene {
            Scene::Soup(s) => s.clone(),
            Scene::Box(bx) => match bx.world_faces() {
                Some(f) => f,
                None => return report,
            },
        };
        let inputs: Vec<Option<Polygon>> = faces
            .iter()
            .enumerate()
            .map(|(i, f)| {
                if f.iter().flatten().any(|c| c.abs() > MAX_COORD) {
                    return None;
                }
                Polygon::from_grid_points(f, i as u32).ok()
            })
            .collect();
        if let Scene::Box(_) = self.scene
            && let Some(i) = inputs.iter().position(Option::is_none)
        {
            fail(
                self,
                format_args!("box face {i} ({:?}) is not a valid polygon", faces[i]),
            );
        }
        let polys: Vec<Polygon> = inputs.iter().flatten().cloned().collect();
        report.polygons = polys.len();
        let tree = BspTree::build(polys, &opts);
        if let Err(e) = tree.sanity_check() {
            fail(self, format_args!("BspTree::sanity_check: {e}"));
        }
        let stats = tree.stats();
        let frags: Vec<&Polygon> = tree.polygons().collect();
        report.fragments = frags.len();
        report.nodes = tree.nodes().len();
        ensure!(
            self,
            stats.nodes == tree.nodes().len() && stats.polygons == frags.len(),
            "stats {stats:?} disagree with {} nodes and {} fragments",
            tree.nodes().len(),
            frags.len()
        );
        ensure!(
            self,
            stats.in_cells + stats.out_cells == stats.nodes + 1,
            "stats {stats:?}: a binary tree has one more leaf than inner nodes"
        );
        self.check_fragments(&inputs, &frags);
        report.traversals = self.check_traversals(&tree, &frags);
        if let Scene::Box(bx) = &self.scene {
            self.check_membership(bx, &tree, &mut report);
        }
        report
    }

    pub(crate) fn check_fragments(&self, inputs: &[Option<Polygon>], frags: &[&Polygon]) {
        let mut by_tag: Vec<Vec<&Polygon>> = vec![Vec::new(); inputs.len()];
        for (i, f) in frags.iter().enumerate() {
            let t = f.tag() as usize;
            ensure!(
                self,
                inputs.get(t).is_some_and(Option::is_some),
                "fragment {i} has tag {t}, which is no valid input polygon"
            );
            by_tag[t].push(f);
        }
        for (t, (input, pieces)) in inputs.iter().zip(&by_tag).enumerate() {
            let Some(input) = input else { continue };
            ensure!(
                self,
                !pieces.is_empty(),
                "input polygon {t} has no fragment"
            );
            check_cover(self, input, pieces, &format!("fragments of polygon {t}"));
        }
    }

    pub(crate) fn check_traversals(&self, tree: &BspTree, frags: &[&Polygon]) -> usize {
        let map = FragmentMap::new(tree, frags);
        let flat = FlatBsp::new(tree);
        ensure!(
            self,
            flat.len() == tree.nodes().len() && flat.polygons().len() == frags.len(),
            "FlatBsp has {} nodes and {} polygons, the tree {} and {}",
            flat.len(),
            flat.polygons().len(),
            tree.nodes().len(),
            frags.len()
        );
        let mut count = 0;
        for (ei, e) in self.eyes.iter().enumerate() {
            let Some(eye) = ViewPoint::new(*e) else {
                continue;
            };
            for order in [Order::BackToFront, Order::FrontToBack] {
                count += 1;
                let what = format!("eye {ei} {e:?}, {order:?}");
                let seq = self.check_visits(&map, &flat, eye, order, &what);
                // painter's order, checked on the first eye only (quadratic)
                if ei > 0 {
                    continue;
                }
                self.check_painter(&map, &seq, eye, order, &what);
            }
        }
        count
    }

    /// Checks that [`BspTree::traverse`] from `eye` in `order` visits
    /// every fragment of `map` exactly once, and that
    /// [`BspTree::traverse_recursive`] and [`FlatBsp::traverse`] (`flat`)
    /// give the same sequence. Returns it (fragment indices).
    pub(crate) fn check_visits(
        &self,
        map: &FragmentMap<'_>,
        flat: &FlatBsp,
        eye: ViewPoint,
        order: Order,
        what: &str,
    ) -> Vec<usize> {
        let (tree, frags, index) = (map.tree, map.frags, &map.index);
        let mut seq = Vec::with_capacity(frags.len());
        tree.traverse(eye, order, |p| {
            seq.push(index.get(&(p as *const Polygon)).copied())
        });
        let mut seen = vec![false; frags.len()];
        for (k, i) in seq.iter().enumerate() {
            let Some(i) = *i else {
                fail(
                    self,
                    format_args!("{what}: visit {k} is not a fragment of the tree"),
                )
            };
            ensure!(
                self,
                !std::mem::replace(&mut seen[i], true),
                "{what}: fragment {i} visited twice"
            );
        }
        ensure!(
            self,
            seq.len() == frags.len(),
            "{what}: {} visits for {} fragments",
            seq.len(),
            frags.len()
        );
        let seq: Vec<usize> = seq.into_iter().flatten().collect();
        let mut rec = Vec::with_capacity(frags.len());
        tree.traverse_recursive(eye, order, |p| {
            rec.push(index.get(&(p as *const Polygon)).copied())
        });
        ensure!(
            self,
            rec.iter().copied().eq(seq.iter().map(|i| Some(*i))),
            "{what}: traverse_recursive gives {rec:?}, traverse {seq:?}"
        );
        let mut k = 0;
        let mut mismatch = None;
        flat.traverse(eye, order, |p| {
            if mismatch.is_none() && seq.get(k).is_none_or(|&i| !same_polygon(p, frags[i])) {
                mismatch = Some(k);
            }
            k += 1;
        });
        ensure!(
            self,
            mismatch.is_none() && k == seq.len(),
            "{what}: FlatBsp::traverse differs from the tree at visit {mismatch:?} \
             ({k} visits, {} fragments)",
            seq.len()
        );
        seq
    }

    /// Checks the painter's order of the visits `seq` from `eye` in
    /// `order`: every pair of fragments in different nodes is separated
    /// by the plane where their paths part, with the eye on the side drawn
    /// last (back to front) or first (front to back).
    pub(crate) fn check_painter(
        &self,
        map: &FragmentMap<'_>,
        seq: &[usize],
        eye: ViewPoint,
        order: Order,
        what: &str,
    ) {
        let (tree, frags) = (map.tree, map.frags);
        for x in 0..seq.len() {
            for y in x + 1..seq.len() {
                let (a, b) = (seq[x], seq[y]);
                let (na, nb) = (map.node_of[a], map.node_of[b]);
                if na == nb {
                    continue;
                }
                let plane = tree.node(map.lca(na, nb)).plane;
                // drawn first: `far`; drawn later: `near`
                let (far, near) = match order {
                    Order::BackToFront => (frags[a], frags[b]),
                    Order::FrontToBack => (frags[b], frags[a]),
                };
                let separated = [plane, plane.flip()].iter().any(|p| {
                    p.classify_viewpoint(eye) != Side::Back
                        && matches!(
                            far.classify(p),
                            PolygonSide::Back | PolygonSide::Coplanar { .. }
                        )
                        && matches!(
                            near.classify(p),
                            PolygonSide::Front | PolygonSide::Coplanar { .. }
                        )
                });
                ensure!(
                    self,
                    separated,
                    "{what}: fragments {a} (visit {x}) and {b} (visit {y}) are not \
                     separated from the eye by {plane:?}"
                );
            }
        }
    }

    pub(crate) fn check_membership(&self, bx: &BoxSolid, tree: &BspTree, report: &mut BuildReport) {
        let oracle = |p: [i128; 3], den: i128| {
            let mut boundary = false;
            for (k, &c) in p.iter().enumerate() {
                let (lo, hi) = (bx.lo[k] as i128 * den, bx.hi[k] as i128 * den);
                if c < lo || c > hi {
                    return Membership::Outside;
                }
                boundary |= c == lo || c == hi;
            }
            if boundary {
                Membership::Boundary
            } else {
                Membership::Inside
            }
        };
        let tally = |m: Membership, report: &mut BuildReport| {
            report.membership[match m {
                Membership::Inside => 0,
                Membership::Outside => 1,
                Membership::Boundary => 2,
            }] += 1;
        };
        let mut probes: Vec<[i64; 3]> = bx.probes.iter().map(|p| p.map(|c| c as i64)).collect();
        // the corners, the centre and a point outside
        for i in 0..8 {
            probes.push([0, 1, 2].map(|k| {
                if i >> k & 1 == 1 {
                    bx.hi[k] as i64
                } else {
                    bx.lo[k] as i64
                }
            }));
        }
        probes.push([0, 1, 2].map(|k| (bx.lo[k] as i64 + bx.hi[k] as i64).div_euclid(2)));
        probes.push([0, 1, 2].map(|k| bx.hi[k] as i64 + 1));
        for (i, p) in probes.iter().enumerate() {
            let Some(q) = bx.to_world(*p) else { continue };
            let want = oracle(p.map(|c| c as i128), 1);
            let got = tree.classify_point(&Point::Grid(q));
            ensure!(
                self,
                got == want,
                "probe {i}: box point {p:?} (grid {q:?}) is {want:?}, classify_point says {got:?}"
            );
            tally(want, report);
        }
        let minv = bx.inverse_rows();
        for (i, (num, den)) in bx.rational_probes.iter().enumerate() {
            if *den <= 0 {
                continue;
            }
            // plane k: den * (minv_k · (q - offset)) - num_k = 0
            let planes: Option<Vec<Plane>> = (0..3)
                .map(|k| {
                    let n = minv[k].map(|c| c as i128 * *den as i128);
                    let d: i128 =
                        -(0..3).map(|j| n[j] * bx.offset[j] as i128).sum::<i128>() - num[k] as i128;
                    let n: Option<[i64; 3]> = n
                        .iter()
                        .map(|c| i64::try_from(*c).ok())
                        .collect::<Option<Vec<_>>>()
                        .map(|v| [v[0], v[1], v[2]]);
                    Plane::new(n?, d)
                })
                .collect();
            let Some(planes) = planes else { continue };
            let Some(q) = Point::from_planes(&planes[0], &planes[1], &planes[2]) else {
                fail(
                    self,
                    format_args!("rational probe {i}: the three planes {planes:?} do not meet"),
                );
            };
            let want = oracle(num.map(|c| c as i128), *den as i128);
            let got = tree.classify_point(&q);
            ensure!(
                self,
                got == want,
                "rational probe {i}: box point {num:?}/{den} ({q:?}) is {want:?}, \
                 classify_point says {got:?}"
            );
            tally(want, report);
            report.implicit_probes += 1;
        }
    }
}

/// A built tree's fragments and where they sit in it: what the traversal
/// checks of [`BuildInput::check`] compare visits with.
pub(crate) struct FragmentMap<'a> {
    tree: &'a BspTree,
    frags: &'a [&'a Polygon],
    /// Each fragment's index, by address.
    index: HashMap<*const Polygon, usize>,
    /// The node holding each fragment.
    node_of: Vec<NodeId>,
    /// Each node's parent.
    parent: Vec<Option<NodeId>>,
    /// Each node's depth.
    depth: Vec<usize>,
}

impl<'a> FragmentMap<'a> {
    /// The index, node, and each node's parent and depth of `tree`'s
    /// fragments `frags`.
    pub(crate) fn new(tree: &'a BspTree, frags: &'a [&'a Polygon]) -> Self {
        let index: HashMap<*const Polygon, usize> = frags
            .iter()
            .enumerate()
            .map(|(i, p)| (*p as *const Polygon, i))
            .collect();
        // the node holding each fragment, and each node's parent and depth
        let mut node_of = vec![0 as NodeId; frags.len()];
        let mut parent: Vec<Option<NodeId>> = vec![None; tree.nodes().len()];
        let mut depth = vec![0usize; tree.nodes().len()];
        for (id, n) in tree.nodes().iter().enumerate() {
            for p in &n.polygons {
                node_of[index[&(p as *const Polygon)]] = id as NodeId;
            }
        }
        let mut stack = vec![(tree.root(), None, 0)];
        while let Some((link, up, d)) = stack.pop() {
            if let Link::Node(id) = link {
                parent[id as usize] = up;
                depth[id as usize] = d;
                let n = tree.node(id);
                stack.push((n.front, Some(id), d + 1));
                stack.push((n.back, Some(id), d + 1));
            }
        }
        FragmentMap {
            tree,
            frags,
            index,
            node_of,
            parent,
            depth,
        }
    }

    /// The lowest common ancestor of nodes `a` and `b`: the node where
    /// their paths from the root part.
    pub(crate) fn lca(&self, mut a: NodeId, mut b: NodeId) -> NodeId {
        while a != b {
            if self.depth[a as usize] >= self.depth[b as usize] {
                a = self.parent[a as usize].expect("a deeper node has a parent");
            } else {
                b = self.parent[b as usize].expect("a deeper node has a parent");
            }
        }
        a
    }
}

impl BoxSolid {
    /// Box coordinates to world grid coordinates, `None` outside the grid.
    pub(crate) fn to_world(&self, p: [i64; 3]) -> Option<GridPoint> {
        let mut q = p;
        for &(i, j, s) in &self.shears {
            if i % 3 != j % 3 {
                q[i % 3] += s as i64 * q[j % 3];
            }
        }
        if self.mirror {
            q[0] = -q[0];
        }
        in_grid([0, 1, 2].map(|k| q[k] + self.offset[k] as i64))
    }

    /// The rows of the inverse of the linear part.
    pub(crate) fn inverse_rows(&self) -> [[i64; 3]; 3] {
        let inv = |mut q: [i64; 3]| {
            if self.mirror {
                q[0] = -q[0];
            }
            for &(i, j, s) in self.shears.iter().rev() {
                if i % 3 != j % 3 {
                    q[i % 3] -= s as i64 * q[j % 3];
                }
            }
            q
        };
        let cols = [inv([1, 0, 0]), inv([0, 1, 0]), inv([0, 0, 1])];
        [0, 1, 2].map(|r| [cols[0][r], cols[1][r], cols[2][r]])
    }

    pub(crate) fn valid(&self) -> bool {
        (0..3).all(|k| self.lo[k] < self.hi[k])
            && self.shears.iter().all(|&(_, _, s)| (-8..=8).contains(&s))
    }

    pub(crate) fn world_corners(&self) -> Option<Vec<GridPoint>> {
        if !self.valid() {
            return None;
        }
        (0..8)
            .map(|i: usize| {
                self.to_world([0, 1, 2].map(|k| {
                    if i >> k & 1 == 1 {
                        self.hi[k] as i64
                    } else {
                        self.lo[k] as i64
                    }
                }))
            })
            .collect()
    }

    /// The faces in world coordinates, outward and counter-clockwise;
    /// `None` if the box is invalid or leaves the grid.
    pub(crate) fn world_faces(&self) -> Option<Vec<Vec<GridPoint>>> {
        self.world_corners()?;
        let xs: Vec<Vec<i64>> = (0..3)
            .map(|k| {
                let (lo, hi, s) = (self.lo[k], self.hi[k], self.splits[k]);
                if lo < s && s < hi {
                    vec![lo as i64, s as i64, hi as i64]
                } else {
                    vec![lo as i64, hi as i64]
                }
            })
            .collect();
        let mut faces = Vec::new();
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            for high in [false, true] {
                let val = if high { self.hi[a] } else { self.lo[a] } as i64;
                let tri = self.triangulate >> (2 * a + usize::from(high)) & 1 == 1;
                for ib in 0..xs[b].len() - 1 {
                    for ic in 0..xs[c].len() - 1 {
                        let corner = |ub: usize, uc: usize| {
                            let mut p = [0; 3];
                            p[a] = val;
                            p[b] = xs[b][ub];
                            p[c] = xs[c][uc];
                            self.to_world(p)
                        };
                        let mut q = [
                            corner(ib, ic)?,
                            corner(ib + 1, ic)?,
                            corner(ib + 1, ic + 1)?,
                            corner(ib, ic + 1)?,
                        ];
                        if !high {
                            q.reverse();
                        }
                        let mut polys: Vec<Vec<GridPoint>> = if !tri {
                            vec![q.to_vec()]
                        } else if self.triangulate & 64 == 0 {
                            vec![vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]]
                        } else {
                            vec![vec![q[1], q[2], q[3]], vec![q[1], q[3], q[0]]]
                        };
                        if self.mirror {
                            polys.iter_mut().for_each(|p| p.reverse());
                        }
                        faces.extend(polys);
                    }
                }
            }
        }
        Some(faces)
    }
}

pub(crate) fn decode_box(b: &mut Bytes<'_>) -> BoxSolid {
    let mut lo = [0; 3];
    let mut hi = [0; 3];
    let mut splits = [0; 3];
    for k in 0..3 {
        let (mut l, mut h) = (b.coord(), b.coord());
        if l > h {
            (l, h) = (h, l);
        }
        if l == h {
            if h < MAX_COORD {
                h += 1;
            } else {
                l -= 1;
            }
        }
        lo[k] = l;
        hi[k] = h;
        splits[k] = b.coord();
    }
    let triangulate = b.u8();
    let shears = [0, 1, 2].map(|_| (b.below(3), b.below(3), (b.u8() as i8 % 9) as i32));
    let mirror = b.u8() & 1 == 1;
    let offset = [0, 1, 2].map(|_| match b.u8() % 3 {
        0 => 0,
        1 => b.u16() as i16 as i32,
        _ => ((b.u32() as i64).rem_euclid((1 << 25) + 1) - (1 << 24)) as i32,
    });
    let axis_value = |b: &mut Bytes<'_>, k: usize| -> i32 {
        let (l, h, s) = (lo[k] as i64, hi[k] as i64, splits[k] as i64);
        clamp_coord(match b.u8() % 8 {
            0 => l - 1,
            1 => l,
            2 => l + 1,
            3 => s,
            4 => h - 1,
            5 => h,
            6 => h + 1,
            _ => b.coord() as i64,
        })
    };
    let n = b.below(9);
    let probes = (0..n)
        .map(|_| [axis_value(b, 0), axis_value(b, 1), axis_value(b, 2)])
        .collect();
    let n = b.below(5);
    let rational_probes = (0..n)
        .map(|_| {
            let den: i64 = match b.u8() % 5 {
                0 => 1,
                1 => 2,
                2 => 3,
                3 => 1 << (b.u8() % 25),
                _ => b.u32() as i64 % (1 << 24) + 1,
            };
            let num = [0, 1, 2].map(|k| {
                let r = (b.u8() % 3) as i64 - 1;
                let base = |v: i32| v as i64 * den;
                match b.u8() % 5 {
                    0 => base(lo[k]) + r,
                    1 => base(hi[k]) + r,
                    2 => base(splits[k]) + r,
                    3 => (base(lo[k]) + base(hi[k])) / 2 + r,
                    _ => b.u64() as i64,
                }
            });
            (num, den)
        })
        .collect();
    BoxSolid {
        lo,
        hi,
        splits,
        triangulate,
        shears,
        mirror,
        offset,
        probes,
        rational_probes,
    }
}

pub(crate) fn decode_soup(b: &mut Bytes<'_>) -> Vec<Vec<GridPoint>> {
    let mut pool: Vec<GridPoint> = Vec::new();
    for _ in 0..b.below(9) {
        let p = b.point(&pool);
        pool.push(p);
    }
    let n = 1 + b.below(12);
    let mut polys: Vec<Vec<GridPoint>> = Vec::with_capacity(n);
    for _ in 0..n {
        let mode = b.u8() % 7;
        let earlier = if polys.is_empty() || !(1..=4).contains(&mode) {
            None
        } else {
            Some(polys[b.below(polys.len())].clone())
        };
        let p = match (mode, earlier) {
            // a triangle on an edge of an earlier polygon, on the other side
            (1, Some(e)) if !e.is_empty() => {
                let i = b.below(e.len());
                let (u, v) = (e[i], e[(i + 1) % e.len()]);
                vec![v, u, b.point(&pool)]
            }
            // the same polygon reversed, or repeated
            (2, Some(e)) => e.into_iter().rev().collect(),
            (3, Some(e)) => e,
            // translated
            (4, Some(e)) => {
                let d = [0, 1, 2].map(|_| b.u8() as i8 as i64);
                e.iter()
                    .map(|p| [0, 1, 2].map(|k| clamp_coord(p[k] as i64 + d[k])))
                    .collect()
            }
            (5, _) => template_polygon(b, &pool).unwrap_or_default(),
            // vertices from the pool
            (6, _) if pool.len() >= 3 => {
                let k = 3 + b.below(2);
                (0..k).map(|_| pool[b.below(pool.len())]).collect()
            }
            _ => {
                let k = 3 + b.below(3);
                (0..k).map(|_| b.point(&pool)).collect()
            }
        };
        pool.extend(p.iter().take(4));
        pool.truncate(16);
        polys.push(p);
    }
    polys
}
