//! Building a tree: an autopartition grown with an explicit stack, the
//! planes chosen by sampling (or replayed from another tree), and pieces
//! pushed down to the cells they land in.

use crate::kernel::{Plane, Polygon, PolygonSide, Split};

use super::{BspTree, BuildOptions, Cell, Link, Node, NodeId, SplitMix};

#[derive(Clone, Copy)]
enum Slot {
    Root,
    Front(NodeId),
    Back(NodeId),
}

/// Splits a list by `plane` into (coplanar, front, back).
pub(super) fn partition_list(
    polys: Vec<Polygon>,
    plane: &Plane,
) -> (Vec<Polygon>, Vec<Polygon>, Vec<Polygon>) {
    let (mut on, mut front, mut back) = (Vec::new(), Vec::new(), Vec::new());
    for p in polys {
        match p.split(plane) {
            Split::Front(p) => front.push(p),
            Split::Back(p) => back.push(p),
            Split::Coplanar { polygon, .. } => on.push(polygon),
            Split::Spanning { front: f, back: b } => {
                front.push(f);
                back.push(b);
            }
        }
    }
    (on, front, back)
}

/// [`partition_list`] of polygons whose sides of `plane` are known
/// (`sides`, [`Polygon::classify`]'s): only the spanning ones are looked
/// at again, to be split, and each list is made at its size.
fn partition_known(
    polys: Vec<Polygon>,
    plane: &Plane,
    sides: &[PolygonSide],
) -> (Vec<Polygon>, Vec<Polygon>, Vec<Polygon>) {
    let (mut n_on, mut n_front, mut n_back) = (0, 0, 0);
    for s in sides {
        match s {
            PolygonSide::Front => n_front += 1,
            PolygonSide::Back => n_back += 1,
            PolygonSide::Coplanar { .. } => n_on += 1,
            PolygonSide::Spanning => {
                n_front += 1;
                n_back += 1;
            }
        }
    }
    let (mut on, mut front, mut back) = (
        Vec::with_capacity(n_on),
        Vec::with_capacity(n_front),
        Vec::with_capacity(n_back),
    );
    for (p, side) in polys.into_iter().zip(sides) {
        match side {
            PolygonSide::Front => front.push(p),
            PolygonSide::Back => back.push(p),
            PolygonSide::Coplanar { .. } => on.push(p),
            PolygonSide::Spanning => match p.split(plane) {
                Split::Spanning { front: f, back: b } => {
                    front.push(f);
                    back.push(b);
                }
                _ => unreachable!("a spanning polygon spans the plane"),
            },
        }
    }
    (on, front, back)
}

/// Every polygon's side of `plane` written to `sides`, in parallel for a
/// long list.
fn sides_of(polys: &[Polygon], plane: &Plane, sides: &mut Vec<PolygonSide>) {
    sides.clear();
    if polys.len() > PARALLEL_LIST {
        sides.resize(polys.len(), PolygonSide::Front);
        crate::par::for_each_mut(sides, |i, s| *s = polys[i].classify(plane));
    } else {
        sides.extend(polys.iter().map(|p| p.classify(plane)));
    }
}

/// `true` if cutting by a plane of which the polygons lie on `sides`
/// leaves each side with at most three quarters of them (spanning ones
/// count on both sides) and neither side empty. Decided before anything
/// is split, so a rejected cut costs no fragments; without it, long
/// parallel slivers would be cut again and again next to the previous cut.
fn cut_balances(sides: &[PolygonSide]) -> bool {
    let (mut front, mut back) = (0usize, 0usize);
    for s in sides {
        match s {
            PolygonSide::Front => front += 1,
            PolygonSide::Back => back += 1,
            PolygonSide::Spanning => {
                front += 1;
                back += 1;
            }
            PolygonSide::Coplanar { .. } => {}
        }
    }
    let limit = sides.len() * 3 / 4;
    front > 0 && back > 0 && front <= limit && back <= limit
}

/// An axis-aligned plane `x_k = m` through the median of the polygons'
/// first-vertex coordinate along the longest axis of their bounding box.
/// How the plane is chosen does not affect exactness, so `f64` is fine here.
fn balance_cut(polys: &[Polygon]) -> Option<Plane> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut firsts: Vec<[f64; 3]> = Vec::with_capacity(polys.len());
    for p in polys {
        let v = p.vertices()[0].approx_f64();
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
        firsts.push(v);
    }
    let k = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))?;
    let mid = firsts.len() / 2;
    firsts.select_nth_unstable_by(mid, |a, b| a[k].total_cmp(&b[k]));
    let m = firsts[mid][k].round() as i128;
    let mut n = [0i64; 3];
    n[k] = 1;
    Plane::new(n, -m)
}

fn choose_plane(polys: &[Polygon], opts: &BuildOptions, rng: &mut SplitMix) -> Plane {
    choose_plane_sides(polys, opts, rng, &mut Vec::new()).0.0
}

/// [`choose_plane`], and whether `sides` holds every polygon's side of
/// the chosen plane ([`Polygon::classify`]): so when the sample is the
/// whole list, which the scoring classified against each candidate.
fn choose_plane_sides(
    polys: &[Polygon],
    opts: &BuildOptions,
    rng: &mut SplitMix,
    sides: &mut Vec<PolygonSide>,
) -> ((Plane, bool), bool) {
    let n = polys.len();
    if n <= 2 {
        return ((*polys[0].support(), false), false);
    }
    let k = opts.candidates.min(n);
    let s = opts.sample.min(n);
    let sample: Vec<usize> = if s == n {
        (0..n).collect()
    } else {
        (0..s).map(|_| rng.below(n)).collect()
    };
    // the best candidate's sides, and the current one's
    let mut these: Vec<PolygonSide> = Vec::with_capacity(s);
    sides.clear();
    let mut best = (u64::MAX, *polys[0].support(), false);
    let mut tried: smallvec::SmallVec<[Plane; 8]> = smallvec::SmallVec::new();
    for c in 0..k {
        let plane = if k == n {
            *polys[c].support()
        } else {
            *polys[rng.below(n)].support()
        };
        // a plane drawn again scores as it did, which does not beat itself
        if tried.contains(&plane) {
            continue;
        }
        tried.push(plane);
        let (mut f, mut b, mut sp) = (0u64, 0u64, 0u64);
        these.clear();
        for &i in &sample {
            let side = polys[i].classify(&plane);
            match side {
                PolygonSide::Front => f += 1,
                PolygonSide::Back => b += 1,
                PolygonSide::Spanning => sp += 1,
                PolygonSide::Coplanar { .. } => {}
            }
            these.push(side);
        }
        let score = opts.split_weight as u64 * sp + f.abs_diff(b);
        if score < best.0 {
            // lopsided: the smaller side and the plane itself each hold
            // under an eighth of the sample
            let on = s as u64 - f - b - sp;
            best = (score, plane, 8 * f.min(b) < s as u64 && 8 * on < s as u64);
            std::mem::swap(sides, &mut these);
        }
    }
    ((best.1, s == n), best.2)
}

/// A node's cut: its plane, the polygons in the plane, and the lists in
/// front of it and behind it.
type Cut = (Plane, Vec<Polygon>, Vec<Polygon>, Vec<Polygon>);

/// The tree `split` grows from `polygons`: a non-empty list becomes a node
/// by the cut `split` makes of it (given what the caller keeps with the
/// list, `at`, and giving that of the front and back lists); an empty one
/// is a leaf, inside behind its parent's plane and outside elsewhere.
/// Nodes are numbered in the order they are made, front subtree first;
/// an explicit stack, so any depth is fine.
pub(super) fn grow<A>(
    polygons: Vec<Polygon>,
    at: A,
    mut split: impl FnMut(Vec<Polygon>, A) -> (Cut, A, A),
) -> BspTree {
    let mut tree = BspTree {
        nodes: Vec::new(),
        root: Link::Cell(Cell::Out),
    };
    let mut stack: Vec<(Vec<Polygon>, A, Slot)> = vec![(polygons, at, Slot::Root)];
    while let Some((polys, at, slot)) = stack.pop() {
        let link = if polys.is_empty() {
            Link::Cell(match slot {
                Slot::Back(_) => Cell::In,
                Slot::Front(_) | Slot::Root => Cell::Out,
            })
        } else {
            let ((plane, on, front, back), at_front, at_back) = split(polys, at);
            let id = tree.add_node(plane, on);
            stack.push((back, at_back, Slot::Back(id)));
            stack.push((front, at_front, Slot::Front(id)));
            Link::Node(id)
        };
        tree.hang(slot, link);
    }
    tree
}

/// Lists longer than this are cut first, one after the other, at the top
/// of a [`BspTree::build`]; the shorter lists they leave are then grown in
/// parallel.
const PARALLEL_LIST: usize = 1 << 15;

/// A balance cut of a list longer than the options' threshold, where one
/// balances ([`cut_balances`]), with every polygon's side of it in
/// `sides` (written whatever the answer).
fn balance(polys: &[Polygon], opts: &BuildOptions, sides: &mut Vec<PolygonSide>) -> Option<Plane> {
    if opts.cut_threshold == 0 || polys.len() <= opts.cut_threshold {
        return None;
    }
    let cut = balance_cut(polys)?;
    sides_of(polys, &cut, sides);
    cut_balances(sides).then_some(cut)
}

/// The cut [`BspTree::build`] makes of a list (`scratch`: room for two
/// planes' sides of every polygon).
fn cut(
    polys: Vec<Polygon>,
    opts: &BuildOptions,
    rng: &mut SplitMix,
    scratch: &mut [Vec<PolygonSide>; 2],
) -> Cut {
    let [sides, spare] = scratch;
    // a balance cut, tried first with `cut_always`, else where the best
    // face plane is lopsided; `known`: `sides` hold every polygon's side
    // of the plane (the balance cut's are found in `spare`, so that a
    // rejected one leaves the face plane's)
    let (plane, known) = match opts
        .cut_always
        .then(|| balance(&polys, opts, sides))
        .flatten()
    {
        Some(cut) => (cut, true),
        None => {
            let ((plane, known), lopsided) = choose_plane_sides(&polys, opts, rng, sides);
            match (!opts.cut_always && lopsided)
                .then(|| balance(&polys, opts, spare))
                .flatten()
            {
                Some(cut) => {
                    std::mem::swap(sides, spare);
                    (cut, true)
                }
                None => (plane, known),
            }
        }
    };
    let (on, front, back) = if known {
        partition_known(polys, &plane, sides)
    } else if polys.len() > PARALLEL_LIST {
        sides_of(&polys, &plane, sides);
        partition_known(polys, &plane, sides)
    } else {
        partition_list(polys, &plane)
    };
    (plane, on, front, back)
}

/// The tree of `polygons` grown on one thread from the random stream
/// `seed`.
fn build_one(polygons: Vec<Polygon>, opts: &BuildOptions, seed: u64) -> BspTree {
    let mut rng = SplitMix(seed);
    let mut scratch = [Vec::new(), Vec::new()];
    grow(polygons, (), |polys, ()| {
        (cut(polys, opts, &mut rng, &mut scratch), (), ())
    })
}

/// `link` of a tree whose nodes were moved `base` places on.
fn shifted(link: Link, base: usize) -> Link {
    match link {
        Link::Node(id) => Link::Node(id + base as NodeId),
        cell => cell,
    }
}

impl BspTree {
    /// A tree of `polygons`: every partitioning plane is the support
    /// plane of an input polygon, but for the balance cuts of long lists
    /// whose best polygon plane is lopsided
    /// ([`BuildOptions::cut_threshold`]; none with 0, a pure
    /// autopartition); coplanar polygons of both
    /// orientations stay at their node. Uses an explicit stack, so any
    /// depth is fine.
    ///
    /// Lists of more than 2^15 polygons are cut first, one after the
    /// other; the shorter lists they leave are grown in parallel, each
    /// from its own random stream (drawn from the seed and the list's
    /// place), so the tree is the same for every thread count. A build of
    /// fewer polygons is one list, grown from the seed alone.
    pub fn build(polygons: Vec<Polygon>, opts: &BuildOptions) -> BspTree {
        if polygons.len() <= PARALLEL_LIST {
            return build_one(polygons, opts, opts.seed);
        }
        let mut tree = BspTree {
            nodes: Vec::new(),
            root: Link::Cell(Cell::Out),
        };
        // the long lists cut level by level, those of a level in parallel,
        // each from a random stream of its own (drawn from its parent's);
        // the shorter lists left, with where they hang and their streams
        let mut level = vec![(polygons, Slot::Root, opts.seed)];
        let mut left: Vec<(Vec<Polygon>, Slot, u64)> = Vec::new();
        while !level.is_empty() {
            let (long, short): (Vec<_>, Vec<_>) =
                level.into_iter().partition(|l| l.0.len() > PARALLEL_LIST);
            left.extend(short);
            let cuts: Vec<(Cut, Slot, [u64; 2])> =
                crate::par::map_vec(long, |(polys, slot, seed)| {
                    let mut rng = SplitMix(seed);
                    let cut = cut(polys, opts, &mut rng, &mut Default::default());
                    (cut, slot, [rng.next_u64(), rng.next_u64()])
                });
            level = Vec::new();
            for ((plane, on, front, back), slot, [f, b]) in cuts {
                let id = tree.add_node(plane, on);
                tree.hang(slot, Link::Node(id));
                level.push((front, Slot::Front(id), f));
                level.push((back, Slot::Back(id), b));
            }
        }
        // the lists left grown in parallel, the longest started first;
        // their nodes then follow the top's, in the lists' order
        let mut jobs: Vec<(usize, Vec<Polygon>, u64)> = (left.iter_mut().enumerate())
            .map(|(i, (polys, _, seed))| (i, std::mem::take(polys), *seed))
            .collect();
        jobs.sort_by_key(|j| std::cmp::Reverse(j.1.len()));
        let mut grown: Vec<(usize, BspTree)> =
            crate::par::map_vec(jobs, |(i, polys, seed)| (i, build_one(polys, opts, seed)));
        grown.sort_by_key(|g| g.0);
        tree.nodes
            .reserve(grown.iter().map(|g| g.1.nodes.len()).sum());
        for ((_, slot, _), (_, sub)) in left.into_iter().zip(grown) {
            let base = tree.nodes.len();
            let link = match sub.root {
                // an empty list: the leaf `grow` makes of it
                Link::Cell(_) => Link::Cell(match slot {
                    Slot::Back(_) => Cell::In,
                    Slot::Front(_) | Slot::Root => Cell::Out,
                }),
                root => shifted(root, base),
            };
            tree.nodes.extend(sub.nodes.into_iter().map(|mut n| {
                n.front = shifted(n.front, base);
                n.back = shifted(n.back, base);
                n
            }));
            tree.hang(slot, link);
        }
        tree
    }

    /// A new node of `plane` holding `polygons`, its leaves as `grow`
    /// makes them (outside in front, inside behind) until children hang
    /// there.
    fn add_node(&mut self, plane: Plane, polygons: Vec<Polygon>) -> NodeId {
        self.nodes.push(Node {
            plane,
            polygons,
            front: Link::Cell(Cell::Out),
            back: Link::Cell(Cell::In),
        });
        (self.nodes.len() - 1) as NodeId
    }

    /// Hangs `link` at `slot`.
    fn hang(&mut self, slot: Slot, link: Link) {
        match slot {
            Slot::Root => self.root = link,
            Slot::Front(id) => self.nodes[id as usize].front = link,
            Slot::Back(id) => self.nodes[id as usize].back = link,
        }
    }

    /// A tree from its nodes and root (indices into `nodes`; every node
    /// reached once).
    pub(crate) fn from_parts(nodes: Vec<Node>, root: Link) -> BspTree {
        BspTree { nodes, root }
    }

    /// This tree's splitting choices replayed on other copies of its
    /// polygons (moved, or snapped again after a motion), tagged as this
    /// tree's polygons are: where this tree split by the plane of face
    /// `t`, the replay splits by the plane of `t`'s new copy, without a
    /// candidate search. Where a copy is missing from its node's list, or
    /// polygons reach what was a leaf here, the replay chooses as
    /// [`BspTree::build`] does with `fallback`. The result is the same
    /// tree wherever the new coordinates keep every polygon on the same
    /// side of every plane, and a valid autopartition in any case.
    pub fn replay(&self, polygons: Vec<Polygon>, fallback: &BuildOptions) -> BspTree {
        let mut rng = SplitMix(fallback.seed);
        // each list with the node of this tree it stands at
        grow(polygons, self.root_id(), |polys, at| {
            let old = at.map(|i| &self.nodes[i as usize]);
            // the face whose plane this tree chose here
            let chosen = old.and_then(|n| {
                let t = n.polygons.iter().find(|p| p.support() == &n.plane)?.tag();
                polys.iter().find(|p| p.tag() == t).map(|p| *p.support())
            });
            let plane = chosen.unwrap_or_else(|| choose_plane(&polys, fallback, &mut rng));
            let (on, front, back) = partition_list(polys, &plane);
            let child = |l: Link| match l {
                Link::Node(j) => Some(j),
                Link::Cell(_) => None,
            };
            let (f, b) = old.map_or((None, None), |n| (child(n.front), child(n.back)));
            ((plane, on, front, back), f, b)
        })
    }

    /// Splits `poly` down the tree by the node planes: the pieces, each with
    /// the cell it lands in. A piece lying in a node's plane goes to the
    /// front (as [`crate::Partition::push_down`]).
    pub fn push_down(&self, poly: Polygon) -> Vec<(Polygon, Cell)> {
        push_down_by(poly, self.root, |l| match l {
            Link::Cell(c) => Err(c),
            Link::Node(id) => {
                let n = &self.nodes[id as usize];
                Ok((&n.plane, n.front, n.back))
            }
        })
    }
}

/// Splits `poly` down a tree from `start`: `step(link)` gives a node's
/// plane and its front and back links, or the leaf's label. The pieces,
/// each with the label of the leaf it lands in; a piece lying in a node's
/// plane goes to the front.
pub(crate) fn push_down_by<'t, K: Copy, L>(
    poly: Polygon,
    start: K,
    step: impl Fn(K) -> Result<(&'t Plane, K, K), L>,
) -> Vec<(Polygon, L)> {
    let mut out = Vec::new();
    let mut stack = vec![(poly, start)];
    while let Some((p, k)) = stack.pop() {
        match step(k) {
            Err(x) => out.push((p, x)),
            Ok((plane, front, back)) => match p.split(plane) {
                Split::Front(q) | Split::Coplanar { polygon: q, .. } => stack.push((q, front)),
                Split::Back(q) => stack.push((q, back)),
                Split::Spanning { front: f, back: b } => {
                    stack.push((f, front));
                    stack.push((b, back));
                }
            },
        }
    }
    out
}
