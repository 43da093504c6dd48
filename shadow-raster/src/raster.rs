//! Scan conversion: polygons (any number of rings) clipped in a view's
//! frame, projected to fixed-point pixel coordinates and filled with the
//! top-left rule.
//!
//! **Fixed point.** Screen coordinates are rounded to `1/256` pixel
//! ([`SUB`]) and every coverage decision after that is exact integer
//! arithmetic, as in GPU rasterizers. A pixel is covered when its centre
//! is inside by the *half-open* rule: an edge crosses the rows whose centre
//! `y` satisfies `y0 <= y < y1` (so horizontal edges never count, a top
//! edge's row is in and a bottom edge's row is out), and on a row a pixel
//! whose centre lies exactly on a crossing belongs to the span to its right.
//! That is the top-left rule. Each crossing is computed from the edge's
//! endpoints in a canonical order (upper endpoint first), so two polygons
//! that share an edge compute the same crossings: no crack and no pixel
//! covered twice. Spans are filled even-odd, so rings may be holes.
//!
//! **Clipping.** Before projection, polygons are clipped (Sutherland–
//! Hodgman) to the near plane and to the image widened by a guard band, in
//! frame coordinates. A cut edge's new vertex is computed from the edge's
//! endpoints in a canonical order, so polygons sharing an edge get the
//! same point.
//!
//! **Bands.** The image is cut into bands of rows; polygons are binned by
//! the rows they reach and the bands are filled in parallel. Every result
//! depends only on each pixel's candidates, never on the order of work.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;
use smallvec_lite::Small;

use crate::scene::RasterScene;
use crate::view::{ClipPlane, Kind, View};

/// Fixed-point units per pixel.
pub(crate) const SUB: i64 = 256;
const HALF: i64 = SUB / 2;

/// Rows per band of parallel work.
pub(crate) const BAND: usize = 16;

/// A tiny inline vector, enough for the crossings of one row.
mod smallvec_lite {
    /// Up to 16 values inline, more on the heap.
    pub(crate) enum Small<T: Copy + Default> {
        Inline([T; 16], usize),
        Heap(Vec<T>),
    }

    impl<T: Copy + Default> Small<T> {
        pub(crate) fn new() -> Self {
            Small::Inline([T::default(); 16], 0)
        }
        pub(crate) fn push(&mut self, v: T) {
            match self {
                Small::Inline(a, n) if *n < 16 => {
                    a[*n] = v;
                    *n += 1;
                }
                Small::Inline(a, n) => {
                    let mut h = a[..*n].to_vec();
                    h.push(v);
                    *self = Small::Heap(h);
                }
                Small::Heap(h) => h.push(v),
            }
        }
        pub(crate) fn as_mut_slice(&mut self) -> &mut [T] {
            match self {
                Small::Inline(a, n) => &mut a[..*n],
                Small::Heap(h) => h,
            }
        }
        pub(crate) fn clear(&mut self) {
            match self {
                Small::Inline(_, n) => *n = 0,
                Small::Heap(h) => h.clear(),
            }
        }
    }
}

/// The first row whose centre is at or below fixed-point `y`:
/// `⌈(y − HALF) / SUB⌉ = ⌊(y − HALF + SUB − 1) / SUB⌋`, the floor by an
/// arithmetic shift (`SUB` is a power of two).
#[inline]
fn first_row(y: i64) -> i64 {
    const SHIFT: u32 = SUB.trailing_zeros();
    const _: () = assert!(1 << SHIFT == SUB);
    (y - HALF + SUB - 1) >> SHIFT
}

/// One edge, upper endpoint first (`y0 < y1`), with the exact crossing of
/// the row it was last used on, stepped from row to row without division.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Edge {
    x0: i64,
    y0: i64,
    dx: i64,
    dy: i64,
    /// Rows whose centre it crosses.
    rows: (i64, i64),
    /// The row `q`, `r` are for (`i64::MIN`: none yet).
    next: i64,
    /// `N = q·D + r`, `0 <= r < D`, with `N` the numerator of the crossing
    /// at row `next` and `D = SUB · dy`.
    q: i64,
    r: i64,
    /// One row's step of `N`, `SUB · dx = sq·D + sr` (`sq = i64::MIN`: not
    /// computed yet).
    sq: i64,
    sr: i64,
}

impl Edge {
    /// The edge between two fixed-point points; `None` if horizontal.
    #[inline]
    fn new(a: [i32; 2], b: [i32; 2]) -> Option<Edge> {
        let (a, b) = if (a[1], a[0]) <= (b[1], b[0]) {
            (a, b)
        } else {
            (b, a)
        };
        let (x0, y0, x1, y1) = (a[0] as i64, a[1] as i64, b[0] as i64, b[1] as i64);
        if y0 == y1 {
            return None;
        }
        Some(Edge {
            x0,
            y0,
            dx: x1 - x0,
            dy: y1 - y0,
            rows: (first_row(y0), first_row(y1)),
            next: i64::MIN,
            q: 0,
            r: 0,
            sq: i64::MIN,
            sr: 0,
        })
    }

    /// The first pixel of row `y` whose centre is at or right of the
    /// crossing: `ceil(N / D)` with `N = x0·dy + dx·(yc − y0) − dy·SUB/2`
    /// (`yc` the row's centre in fixed point), exactly. Rows asked in
    /// increasing order cost no division after the second.
    #[inline]
    fn crossing(&mut self, y: i64) -> i64 {
        let d = SUB * self.dy;
        if self.next != y {
            let py = y * SUB + HALF;
            let n = self.x0 * self.dy + self.dx * (py - self.y0) - HALF * self.dy;
            self.q = n.div_euclid(d);
            self.r = n.rem_euclid(d);
        }
        let x = self.q + (self.r > 0) as i64;
        if y + 1 < self.rows.1 {
            if self.sq == i64::MIN {
                self.sq = (SUB * self.dx).div_euclid(d);
                self.sr = (SUB * self.dx).rem_euclid(d);
            }
            self.q += self.sq;
            self.r += self.sr;
            // carry without a branch: it is a coin toss on most edges
            let carry = (self.r >= d) as i64;
            self.q += carry;
            self.r -= carry * d;
            self.next = y + 1;
        }
        x
    }
}

/// Polygons in screen space: fixed-point rings, the rows they reach, and
/// per polygon its nearness coefficients and an id.
#[derive(Default)]
pub(crate) struct Screen {
    pub(crate) pts: Vec<[i32; 2]>,
    /// Ring `k` is `pts[ring_start[k]..ring_start[k + 1]]`.
    ring_start: Vec<u32>,
    /// Polygon `i` is rings `poly_ring[i]..poly_ring[i + 1]`.
    poly_ring: Vec<u32>,
    pub(crate) rows: Vec<(i32, i32)>,
    pub(crate) cols: Vec<(i32, i32)>,
    pub(crate) coeffs: Vec<[f64; 3]>,
    pub(crate) id: Vec<u32>,
}

impl Screen {
    fn new() -> Screen {
        Screen {
            ring_start: vec![0],
            poly_ring: vec![0],
            ..Screen::default()
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.id.len()
    }

    fn rings(&self, i: usize) -> impl Iterator<Item = &[[i32; 2]]> + '_ {
        (self.poly_ring[i] as usize..self.poly_ring[i + 1] as usize)
            .map(move |k| &self.pts[self.ring_start[k] as usize..self.ring_start[k + 1] as usize])
    }

    /// Empties the screen, keeping its buffers.
    fn clear(&mut self) {
        self.pts.clear();
        self.ring_start.clear();
        self.ring_start.push(0);
        self.poly_ring.clear();
        self.poly_ring.push(0);
        self.rows.clear();
        self.cols.clear();
        self.coeffs.clear();
        self.id.clear();
    }

    /// The polygons of `parts`, one part after the other, in this
    /// screen's buffers, copied in parallel.
    fn concat(&mut self, parts: &[Screen]) {
        // each part's first point and ring in the whole
        let (mut p0, mut r0) = (
            Vec::with_capacity(parts.len()),
            Vec::with_capacity(parts.len()),
        );
        let (mut p, mut r) = (0u32, 0u32);
        for part in parts {
            p0.push(p);
            r0.push(r);
            p += part.pts.len() as u32;
            r += (part.ring_start.len() - 1) as u32;
        }
        // every array of a part copied by one job (one fork-join for all)
        let lens = |f: fn(&Screen) -> usize| parts.iter().map(f).collect::<Vec<_>>();
        let pts = pieces(&mut self.pts, 0, &lens(|s| s.pts.len()));
        let rings = pieces(&mut self.ring_start, 1, &lens(|s| s.ring_start.len() - 1));
        let polys = pieces(&mut self.poly_ring, 1, &lens(|s| s.poly_ring.len() - 1));
        let rows = pieces(&mut self.rows, 0, &lens(|s| s.rows.len()));
        let cols = pieces(&mut self.cols, 0, &lens(|s| s.cols.len()));
        let coeffs = pieces(&mut self.coeffs, 0, &lens(|s| s.coeffs.len()));
        let id = pieces(&mut self.id, 0, &lens(|s| s.id.len()));
        let jobs: Vec<_> = pts
            .into_iter()
            .zip(rings)
            .zip(polys)
            .zip(rows.into_iter().zip(cols))
            .zip(coeffs.into_iter().zip(id))
            .collect();
        jobs.into_par_iter()
            .zip(parts.par_iter())
            .enumerate()
            .for_each(
                |(k, (((((pts, rings), polys), (rows, cols)), (coeffs, id)), s))| {
                    pts.copy_from_slice(&s.pts);
                    for (d, &v) in rings.iter_mut().zip(&s.ring_start[1..]) {
                        *d = v + p0[k];
                    }
                    for (d, &v) in polys.iter_mut().zip(&s.poly_ring[1..]) {
                        *d = v + r0[k];
                    }
                    rows.copy_from_slice(&s.rows);
                    cols.copy_from_slice(&s.cols);
                    coeffs.copy_from_slice(&s.coeffs);
                    id.copy_from_slice(&s.id);
                },
            );
        self.ring_start[0] = 0;
        self.poly_ring[0] = 0;
    }

    /// The edges of polygon `i`.
    pub(crate) fn edges(&self, i: usize, out: &mut Vec<Edge>) {
        out.clear();
        for ring in self.rings(i) {
            let n = ring.len();
            for k in 0..n {
                if let Some(e) = Edge::new(ring[k], ring[if k + 1 == n { 0 } else { k + 1 }]) {
                    out.push(e);
                }
            }
        }
    }

    /// Calls `span(y, x0..x1)` for every run of covered pixels of polygon
    /// `i` on the rows `rows` (clamped to the image width `width`).
    pub(crate) fn spans(
        &self,
        i: usize,
        rows: Range<i64>,
        width: i64,
        edges: &mut Vec<Edge>,
        mut span: impl FnMut(i64, Range<i64>),
    ) {
        let (r0, r1) = self.rows[i];
        let (y0, y1) = (rows.start.max(r0 as i64), rows.end.min(r1 as i64));
        if y0 >= y1 {
            return;
        }
        self.edges(i, edges);
        fill(edges, y0..y1, width, &mut span);
    }

    /// `true` if polygon `i` covers pixel `(x, y)`.
    pub(crate) fn covers(&self, i: usize, x: i64, y: i64, edges: &mut Vec<Edge>) -> bool {
        let (r0, r1) = self.rows[i];
        let (c0, c1) = self.cols[i];
        if y < r0 as i64 || y >= r1 as i64 || x < c0 as i64 || x >= c1 as i64 {
            return false;
        }
        let mut hit = false;
        self.spans(i, y..y + 1, x + 1, edges, |_, s| hit |= s.contains(&x));
        hit
    }

    /// Nearness of polygon `i` at pixel `(x, y)`.
    #[inline]
    pub(crate) fn nearness(&self, i: usize, x: i64, y: i64) -> f64 {
        nearness(&self.coeffs[i], x, y)
    }
}

/// The nearness `a·xc + (b·yc + c)` at the centre of pixel `(x, y)`: the one
/// formula every method uses, so that equal inputs give equal bits.
#[inline]
pub(crate) fn nearness(k: &[f64; 3], x: i64, y: i64) -> f64 {
    k[0] * (x as f64 + 0.5) + row_term(k, y)
}

/// The row part `b·yc + c` of [`nearness`].
#[inline]
pub(crate) fn row_term(k: &[f64; 3], y: i64) -> f64 {
    k[1] * (y as f64 + 0.5) + k[2]
}

/// Even-odd fill of `edges` on rows `rows`.
fn fill(edges: &mut [Edge], rows: Range<i64>, width: i64, span: &mut impl FnMut(i64, Range<i64>)) {
    let mut xs: Small<i64> = Small::new();
    for y in rows {
        xs.clear();
        for e in edges.iter_mut() {
            if e.rows.0 <= y && y < e.rows.1 {
                xs.push(e.crossing(y));
            }
        }
        let xs = xs.as_mut_slice();
        if xs.len() == 2 {
            let (a, b) = (xs[0].min(xs[1]), xs[0].max(xs[1]));
            let (a, b) = (a.max(0), b.min(width));
            if a < b {
                span(y, a..b);
            }
            continue;
        }
        xs.sort_unstable();
        for pair in xs.chunks_exact(2) {
            let (a, b) = (pair[0].max(0), pair[1].min(width));
            if a < b {
                span(y, a..b);
            }
        }
    }
}

/// A pixel coordinate (within the guard band) in fixed point, rounded to
/// nearest, halves up: `⌊v·SUB + 1/2⌋` (exact: `|v·SUB| < 2^31`, so adding
/// a half does not round). Branch-free and without a library call, since
/// this runs for every vertex and the rounding direction is a coin toss.
#[inline]
fn to_fixed(v: f64) -> i32 {
    // clipping keeps |v| within the guard band; the clamp only tames
    // non-finite input (NaN becomes 0)
    const LIMIT: f64 = (1u64 << 30) as f64;
    let s = (v * SUB as f64).clamp(-LIMIT, LIMIT) + 0.5;
    let i = s as i64;
    (i - ((i as f64) > s) as i64) as i32
}

/// Canonical intersection of segment `ab` with a plane, given the plane's
/// values at both ends (of opposite signs): interpolated from the end
/// inside the plane (`value >= 0`), so that an edge shared by two polygons
/// is cut at the same point whichever way each one runs along it.
///
/// The order is chosen from the values, not from the points' coordinates:
/// comparing coordinates here read single lanes of the corner carried
/// from one iteration of [`clip_ring`]'s loop to the next, and LLVM 22's
/// x86 register allocator then kept that corner's `y` in the spill slot
/// of its `x` (8 bytes, reloaded with `y = 0`) in the fat-LTO release
/// build: `docs/llvm-clip-miscompile/README.md`.
#[inline]
fn cut(a: DVec3, b: DVec3, da: f64, db: f64) -> DVec3 {
    let (a, b, da, db) = if da >= 0.0 {
        (a, b, da, db)
    } else {
        (b, a, db, da)
    };
    a + (b - a) * (da / (da - db))
}

/// Sutherland–Hodgman clip of a ring (frame coordinates) to `n · c + d >= 0`.
pub(crate) fn clip_ring(ring: &[DVec3], (n, d): ClipPlane, out: &mut Vec<DVec3>) {
    out.clear();
    let k = ring.len();
    for i in 0..k {
        let (a, b) = (ring[i], ring[(i + 1) % k]);
        let (da, db) = (n.dot(a) + d, n.dot(b) + d);
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(cut(a, b, da, db));
        }
    }
}

/// Projects polygons into a view. Each polygon is given as rings of world
/// points (`ring_pts(i, k)`), with its plane `n · p + d = 0` for the
/// nearness and an id.
pub(crate) struct Projector<'a> {
    view: &'a View,
    planes: [ClipPlane; 5],
    /// The same planes as bounds: perspective `z >= near`,
    /// `|x| <= gx·z`, `|y| <= gy·z`; orthographic `|x| <= gx`, `|y| <= gy`.
    bounds: Bounds,
}

/// [`View::clip_planes`] as the bounds of a box or a pyramid, tested with
/// the same arithmetic as the planes' `n · c + d >= 0` (each plane has one
/// or two non-zero coefficients, ±1 and a bound), so the decisions agree.
#[derive(Clone, Copy)]
enum Bounds {
    Pyramid { near: f64, gx: f64, gy: f64 },
    Box { hx: f64, hy: f64 },
}

impl Bounds {
    fn of(view: &View, planes: &[ClipPlane; 5]) -> Bounds {
        match view.kind {
            Kind::Perspective { .. } => Bounds::Pyramid {
                near: -planes[0].1,
                gx: planes[1].0.z,
                gy: planes[3].0.z,
            },
            Kind::Orthographic { .. } => Bounds::Box {
                hx: planes[1].1,
                hy: planes[3].1,
            },
        }
    }

    /// `true` if `c` is inside every clip plane.
    #[inline]
    fn inside(self, c: DVec3) -> bool {
        match self {
            Bounds::Pyramid { near, gx, gy } => {
                let (x, y) = (gx * c.z, gy * c.z);
                (c.z - near >= 0.0)
                    & (c.x + x >= 0.0)
                    & (x - c.x >= 0.0)
                    & (y - c.y >= 0.0)
                    & (c.y + y >= 0.0)
            }
            Bounds::Box { hx, hy } => {
                (c.x + hx >= 0.0) & (hx - c.x >= 0.0) & (c.y + hy >= 0.0) & (hy - c.y >= 0.0)
            }
        }
    }
}

impl<'a> Projector<'a> {
    pub(crate) fn new(view: &'a View) -> Projector<'a> {
        let planes = view.clip_planes();
        Projector {
            view,
            planes,
            bounds: Bounds::of(view, &planes),
        }
    }

    #[inline]
    fn fixed(&self, c: DVec3) -> [i32; 2] {
        let (x, y) = self.view.screen(c);
        [to_fixed(x), to_fixed(y)]
    }

    /// Adds one polygon (its rings in world coordinates) to `out`; nothing
    /// if it is out of view or seen edge-on. `coeffs` is its nearness (see
    /// [`View::coeffs`]).
    pub(crate) fn add<'r>(
        &self,
        rings: impl IntoIterator<Item = &'r [DVec3]>,
        coeffs: [f64; 3],
        id: u32,
        out: &mut Screen,
        scratch: &mut (Vec<DVec3>, Vec<DVec3>),
    ) {
        let start_pts = out.pts.len();
        let start_rings = out.ring_start.len();
        let mut bounds = NO_BOUNDS;
        for ring in rings {
            let (a, b) = scratch;
            a.clear();
            a.extend(ring.iter().map(|&p| self.view.frame(p)));
            let clip = self.bounds;
            if !a.iter().fold(true, |all, c| all & clip.inside(*c)) {
                for pl in self.planes {
                    if a.len() < 3 {
                        break;
                    }
                    clip_ring(a, pl, b);
                    std::mem::swap(a, b);
                }
            }
            if a.len() < 3 {
                continue;
            }
            for c in a.iter() {
                push_point(out, self.fixed(*c), &mut bounds);
            }
            out.ring_start.push(out.pts.len() as u32);
        }
        self.close(out, (start_pts, start_rings), bounds, coeffs, id);
    }

    /// Adds polygon `i` of `scene` as [`Projector::add`] does, from its
    /// corners' screen points in `corners` when they are all inside the
    /// clip planes (the same points, computed once per shared vertex).
    #[inline]
    pub(crate) fn add_prim(
        &self,
        scene: &RasterScene,
        i: usize,
        corners: &Corners,
        coeffs: [f64; 3],
        out: &mut Screen,
        scratch: &mut (Vec<DVec3>, Vec<DVec3>),
    ) {
        let range = scene.start[i] as usize..scene.start[i + 1] as usize;
        let verts = &scene.corner[range];
        if !verts.iter().all(|&v| corners.fixed[v as usize].is_some()) {
            self.add([scene.prim(i)], coeffs, i as u32, out, scratch);
            return;
        }
        let start = (out.pts.len(), out.ring_start.len());
        let mut bounds = NO_BOUNDS;
        for &v in verts {
            push_point(
                out,
                corners.fixed[v as usize].expect("checked above"),
                &mut bounds,
            );
        }
        out.ring_start.push(out.pts.len() as u32);
        self.close(out, start, bounds, coeffs, i as u32);
    }

    /// Ends the polygon whose points and rings `out` has from `start` on,
    /// with their bounds `[xmin, ymin, xmax, ymax]`: kept with its rows,
    /// columns, nearness and id if it has a ring and reaches a pixel
    /// centre, else taken back.
    #[inline]
    fn close(
        &self,
        out: &mut Screen,
        (start_pts, start_rings): (usize, usize),
        [xmin, ymin, xmax, ymax]: [i32; 4],
        coeffs: [f64; 3],
        id: u32,
    ) {
        let rows = (
            first_row(ymin as i64).max(0),
            first_row(ymax as i64).min(self.view.height as i64),
        );
        let cols = (
            first_row(xmin as i64).max(0),
            (first_row(xmax as i64) + 1).min(self.view.width as i64),
        );
        if out.ring_start.len() == start_rings || rows.0 >= rows.1 || cols.0 >= cols.1 {
            out.pts.truncate(start_pts);
            out.ring_start.truncate(start_rings);
            return;
        }
        out.poly_ring.push((out.ring_start.len() - 1) as u32);
        out.rows.push((rows.0 as i32, rows.1 as i32));
        out.cols.push((cols.0 as i32, cols.1 as i32));
        out.coeffs.push(coeffs);
        out.id.push(id);
    }
}

/// Bounds `[xmin, ymin, xmax, ymax]` of no point yet.
const NO_BOUNDS: [i32; 4] = [i32::MAX, i32::MAX, i32::MIN, i32::MIN];

/// Adds fixed-point `p` to the current ring of `out`, growing `bounds`.
#[inline]
fn push_point(out: &mut Screen, p: [i32; 2], bounds: &mut [i32; 4]) {
    bounds[0] = bounds[0].min(p[0]);
    bounds[1] = bounds[1].min(p[1]);
    bounds[2] = bounds[2].max(p[0]);
    bounds[3] = bounds[3].max(p[1]);
    out.pts.push(p);
}

/// The screen point of each of a scene's shared vertices in one view, or
/// `None` where the vertex is outside a clip plane (its polygons are then
/// clipped point by point).
#[derive(Default)]
pub(crate) struct Corners {
    fixed: Vec<Option<[i32; 2]>>,
}

impl Corners {
    /// The corners of `scene` in `proj`'s view, in the buffers of earlier
    /// ones.
    pub(crate) fn compute(&mut self, scene: &RasterScene, proj: &Projector<'_>) {
        self.fixed.clear();
        self.fixed
            .par_extend(scene.verts.par_iter().with_min_len(4096).map(|&p| {
                let c = proj.view.frame(p);
                proj.bounds.inside(c).then(|| proj.fixed(c))
            }));
    }
}

/// Projects `count` polygons in parallel: `make(i, projector, out, scratch)`
/// adds polygon `i`. The result keeps the order of `i`.
pub(crate) fn project_all(
    view: &View,
    count: usize,
    make: impl Fn(usize, &Projector<'_>, &mut Screen, &mut (Vec<DVec3>, Vec<DVec3>)) + Sync,
) -> Screen {
    let mut all = Screen::new();
    project_all_into(view, count, make, &mut Vec::new(), &mut all);
    all
}

/// [`project_all`] into `all`, in the buffers of an earlier call (`parts`
/// keeps the per-chunk screens).
pub(crate) fn project_all_into(
    view: &View,
    count: usize,
    make: impl Fn(usize, &Projector<'_>, &mut Screen, &mut (Vec<DVec3>, Vec<DVec3>)) + Sync,
    parts: &mut Vec<Screen>,
    all: &mut Screen,
) {
    const CHUNK: usize = 4096;
    let proj = Projector::new(view);
    parts.resize_with(count.div_ceil(CHUNK), Screen::new);
    parts.par_iter_mut().enumerate().for_each(|(c, out)| {
        out.clear();
        let mut scratch = (Vec::new(), Vec::new());
        for i in c * CHUNK..((c + 1) * CHUNK).min(count) {
            make(i, &proj, out, &mut scratch);
        }
    });
    all.concat(parts);
}

/// `dst` made `lead` values followed by pieces of lengths `lens`, one
/// after the other: the pieces (`dst` keeps its first `lead` values, and
/// the pieces' values are left to be written).
fn pieces<'a, T: Copy + Default>(
    dst: &'a mut Vec<T>,
    lead: usize,
    lens: &[usize],
) -> Vec<&'a mut [T]> {
    let total = lead + lens.iter().sum::<usize>();
    if dst.len() != total {
        dst.resize(total, T::default());
    }
    let mut out = Vec::with_capacity(lens.len());
    let mut rest = &mut dst[lead..];
    for &n in lens {
        let (piece, tail) = rest.split_at_mut(n);
        out.push(piece);
        rest = tail;
    }
    out
}

/// The polygons of `screen` reaching each band of [`BAND`] rows, in
/// polygon order, binned in parallel by runs of [`BIN_RUN`] polygons:
/// a band's polygons are its lists in every run, one run after the other.
#[derive(Default)]
pub(crate) struct Bins {
    runs: Vec<BinRun>,
}

/// Polygons binned per run in [`Bins`].
const BIN_RUN: usize = 16384;

/// One run's bins: band `b` is `list[start[b]..start[b + 1]]`.
#[derive(Default)]
struct BinRun {
    start: Vec<u32>,
    list: Vec<u32>,
}

impl BinRun {
    /// Bins polygons `first..` whose rows are `rows`.
    fn rebuild(&mut self, first: usize, rows: &[(i32, i32)], bands: usize) {
        let band_range = |&(r0, r1): &(i32, i32)| {
            let b0 = r0 as usize / BAND;
            let b1 = (r1 as usize - 1) / BAND + 1;
            b0..b1
        };
        let count = &mut self.start;
        count.clear();
        count.resize(bands + 1, 0);
        for r in rows {
            for b in band_range(r) {
                count[b + 1] += 1;
            }
        }
        for b in 0..bands {
            count[b + 1] += count[b];
        }
        let mut fill = count.clone();
        self.list.clear();
        self.list.resize(count[bands] as usize, 0);
        for (i, r) in rows.iter().enumerate() {
            for b in band_range(r) {
                self.list[fill[b] as usize] = (first + i) as u32;
                fill[b] += 1;
            }
        }
    }

    fn band(&self, b: usize) -> &[u32] {
        &self.list[self.start[b] as usize..self.start[b + 1] as usize]
    }
}

impl Bins {
    pub(crate) fn new(screen: &Screen, height: u32) -> Bins {
        let mut b = Bins::default();
        b.rebuild(screen, height);
        b
    }

    /// The bins of `screen`, in the buffers of earlier ones.
    pub(crate) fn rebuild(&mut self, screen: &Screen, height: u32) {
        self.rebuild_by(screen, height, BIN_RUN);
    }

    /// [`Bins::rebuild`] by runs of `run` polygons.
    fn rebuild_by(&mut self, screen: &Screen, height: u32, run: usize) {
        let bands = (height as usize).div_ceil(BAND);
        let rows = &screen.rows;
        self.runs
            .resize_with(rows.len().div_ceil(run), BinRun::default);
        self.runs
            .par_iter_mut()
            .zip(rows.par_chunks(run))
            .enumerate()
            .for_each(|(k, (bins, rows))| bins.rebuild(k * run, rows, bands));
    }

    /// The polygons reaching band `b`, in polygon order (gathered into
    /// `buf` when there are several runs).
    pub(crate) fn band<'a>(&'a self, b: usize, buf: &'a mut Vec<u32>) -> &'a [u32] {
        match self.runs.as_slice() {
            [] => &[],
            [one] => one.band(b),
            runs => {
                buf.clear();
                for r in runs {
                    buf.extend_from_slice(r.band(b));
                }
                buf
            }
        }
    }
}

/// Runs `f(rows, polygons, pixels)` on every band of `buf` (a `width ×
/// height` image, row-major) in parallel.
pub(crate) fn for_bands<T: Send>(
    buf: &mut [T],
    width: u32,
    bins: &Bins,
    f: impl Fn(Range<i64>, &[u32], &mut [T]) + Sync,
) {
    let w = width as usize;
    buf.par_chunks_mut(BAND * w)
        .enumerate()
        .for_each_init(Vec::new, |polys, (b, chunk)| {
            let y0 = (b * BAND) as i64;
            let rows = y0..y0 + (chunk.len() / w) as i64;
            f(rows, bins.band(b, polys), chunk);
        });
}

/// A vector of `n` copies of `v`, written in parallel: every page is first
/// touched by a write on the thread that fills it (a zeroed allocation
/// written later faults twice, copy-on-write, with TLB shootdowns).
pub(crate) fn filled<T: Copy + Send + Sync>(n: usize, v: T) -> Vec<T> {
    let mut out = Vec::with_capacity(n);
    out.par_extend(rayon::iter::repeat_n(v, n));
    out
}

/// `buf` made `n` long, its values left as they were when it already is
/// (for passes that write every cell), else `n` copies of `v`.
pub(crate) fn reserve_len<T: Copy + Send + Sync>(buf: &mut Vec<T>, n: usize, v: T) {
    if buf.len() != n {
        *buf = filled(n, v);
    }
}

/// [`for_bands`] over two images at once.
pub(crate) fn for_bands2<T: Send, U: Send>(
    a: &mut [T],
    b: &mut [U],
    width: u32,
    bins: &Bins,
    f: impl Fn(Range<i64>, &[u32], &mut [T], &mut [U]) + Sync,
) {
    let w = width as usize;
    a.par_chunks_mut(BAND * w)
        .zip(b.par_chunks_mut(BAND * w))
        .enumerate()
        .for_each_init(Vec::new, |polys, (k, (ca, cb))| {
            let y0 = (k * BAND) as i64;
            let rows = y0..y0 + (ca.len() / w) as i64;
            f(rows, bins.band(k, polys), ca, cb);
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Camera;

    fn fx(x: f64, y: f64) -> [i32; 2] {
        [(x * 256.0) as i32, (y * 256.0) as i32]
    }

    /// Coverage count of a set of fixed-point polygons over a small image.
    fn coverage(polys: &[Vec<[i32; 2]>], w: i64, h: i64) -> Vec<u32> {
        let mut cov = vec![0u32; (w * h) as usize];
        let mut edges = Vec::new();
        for p in polys {
            edges.clear();
            for k in 0..p.len() {
                if let Some(e) = Edge::new(p[k], p[(k + 1) % p.len()]) {
                    edges.push(e);
                }
            }
            fill(&mut edges, 0..h, w, &mut |y, xs| {
                for x in xs {
                    cov[(y * w + x) as usize] += 1;
                }
            });
        }
        cov
    }

    /// `clip_ring` against the plane taken corner by corner: the corners
    /// inside are kept in order from the first, each edge that crosses
    /// the plane adds one point on it and on the edge, and an edge cut
    /// from either end gives the same point. (The fat-LTO miscompile of
    /// `docs/llvm-clip-miscompile` zeroed the first kept corner's `y`.)
    #[test]
    fn clip_ring_keeps_inside_corners_and_cuts_each_crossing_edge_once() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0
        };
        let (mut out, mut back) = (Vec::new(), Vec::new());
        let mut cuts = 0;
        for _ in 0..4000 {
            let k = 3 + (rnd().abs() as usize) % 6;
            let ring: Vec<DVec3> = (0..k).map(|_| DVec3::new(rnd(), rnd(), rnd())).collect();
            let plane = (DVec3::new(rnd(), rnd(), rnd()), rnd());
            let value = |c: DVec3| plane.0.dot(c) + plane.1;
            clip_ring(&ring, plane, &mut out);
            let mut want = Vec::new();
            for i in 0..k {
                let (a, b) = (ring[i], ring[(i + 1) % k]);
                if value(a) >= 0.0 {
                    want.push(Some(a));
                }
                if (value(a) >= 0.0) != (value(b) >= 0.0) {
                    want.push(None);
                }
            }
            assert_eq!(out.len(), want.len(), "{ring:?} {plane:?}");
            let reversed: Vec<DVec3> = ring.iter().rev().copied().collect();
            clip_ring(&reversed, plane, &mut back);
            for (i, (got, w)) in out.iter().zip(&want).enumerate() {
                match w {
                    Some(c) => assert_eq!(got, c, "corner {i} of {ring:?}"),
                    None => {
                        cuts += 1;
                        let scale = plane.0.length() * 20.0 + plane.1.abs();
                        assert!(value(*got).abs() <= 1e-12 * scale, "{got} off the plane");
                        // the same point when the ring runs the other way
                        assert!(back.contains(got), "{got} not in {back:?}");
                    }
                }
            }
        }
        assert!(cuts > 1000, "{cuts} crossing edges");
    }

    #[test]
    fn shared_edges_leave_no_crack_and_no_overlap() {
        // a fan of triangles around a centre on a pixel corner and one on a
        // pixel centre, and a grid of squares whose corners fall on pixel
        // centres: every pixel of the covered square is covered exactly once
        for centre in [(8.0, 8.0), (8.5, 8.5), (7.3, 8.61)] {
            let c = fx(centre.0, centre.1);
            let ring: Vec<[i32; 2]> = [
                (2.0, 2.0),
                (8.5, 1.5),
                (14.0, 2.0),
                (14.5, 8.5),
                (14.0, 14.0),
                (8.5, 14.5),
                (2.0, 14.0),
                (1.5, 8.5),
            ]
            .iter()
            .map(|&(x, y)| fx(x, y))
            .collect();
            let fan: Vec<Vec<[i32; 2]>> = (0..ring.len())
                .map(|k| vec![c, ring[k], ring[(k + 1) % ring.len()]])
                .collect();
            let whole = coverage(std::slice::from_ref(&ring), 16, 16);
            let parts = coverage(&fan, 16, 16);
            assert_eq!(whole, parts, "centre {centre:?}");
            assert!(parts.iter().all(|&c| c <= 1));
        }
        let mut squares = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (1.5 + 3.0 * i as f64, 0.5 + 3.0 * j as f64);
                squares.push(vec![
                    fx(x, y),
                    fx(x + 3.0, y),
                    fx(x + 3.0, y + 3.0),
                    fx(x, y + 3.0),
                ]);
            }
        }
        let cov = coverage(&squares, 16, 16);
        for y in 0..16 {
            for x in 0..16 {
                let inside = (1..13).contains(&x) && (0..12).contains(&y);
                assert_eq!(cov[y * 16 + x], inside as u32, "({x}, {y})");
            }
        }
    }

    #[test]
    fn random_fans_and_strips_tile_exactly() {
        // random convex polygons (vertices on random sub-pixel positions,
        // a third of them exactly on pixel centres or corners) cut into a
        // fan around a random inner point and into a strip of quads: the
        // pieces cover exactly the pixels the polygon covers, each once
        let mut rng = bsp_core::internals::SplitMix(0x7011_1e57);
        let coord = |rng: &mut bsp_core::internals::SplitMix| {
            let base = rng.below(24 * 256) as i32;
            match rng.below(3) {
                0 => base / 256 * 256 + 128,
                1 => base / 256 * 256,
                _ => base,
            }
        };
        for k in 0..300 {
            // a convex polygon around a centre on a pixel centre, a pixel
            // corner or anywhere, its vertices at random sub-pixel places
            let centre = [coord(&mut rng), coord(&mut rng)].map(|v| v % 256 + 12 * 256);
            let n = 3 + rng.below(6);
            let mut angles: Vec<f64> = (0..n)
                .map(|_| rng.below(3600) as f64 / 3600.0 * std::f64::consts::TAU)
                .collect();
            angles.sort_by(f64::total_cmp);
            angles.dedup();
            let gap = angles
                .windows(2)
                .map(|w| w[1] - w[0])
                .chain([angles[0] + std::f64::consts::TAU - angles[angles.len() - 1]])
                .fold(0.0, f64::max);
            if angles.len() < 3 || gap > 0.9 * std::f64::consts::PI {
                continue; // the centre must be inside
            }
            let r = 2000.0 + rng.below(800) as f64;
            let ring: Vec<[i32; 2]> = angles
                .iter()
                .map(|a| {
                    [
                        centre[0] + (r * a.cos()) as i32,
                        centre[1] + (r * a.sin()) as i32,
                    ]
                })
                .collect();
            let whole = coverage(std::slice::from_ref(&ring), 24, 24);
            let fan: Vec<Vec<[i32; 2]>> = (0..ring.len())
                .map(|k| vec![centre, ring[k], ring[(k + 1) % ring.len()]])
                .collect();
            assert_eq!(
                coverage(&fan, 24, 24),
                whole,
                "case {k}: fan of {ring:?} around {centre:?}"
            );
        }
        // a strip of quads sharing random cut lines
        for _ in 0..100 {
            let xs: Vec<i32> = {
                let mut v: Vec<i32> = (0..6).map(|_| coord(&mut rng)).collect();
                v.sort_unstable();
                v.dedup();
                v
            };
            let (y0, y1) = (coord(&mut rng).min(2000), coord(&mut rng).max(3000));
            let quads: Vec<Vec<[i32; 2]>> = xs
                .windows(2)
                .map(|w| vec![[w[0], y0], [w[1], y0 + 300], [w[1], y1], [w[0], y1 - 200]])
                .collect();
            let cov = coverage(&quads, 24, 24);
            assert!(cov.iter().all(|&c| c <= 1), "overlap in {quads:?}");
        }
    }

    #[test]
    fn fixed_point_rounding_is_to_nearest_halves_up() {
        // the branch-free rounding against the rounding it replaced
        let old = |v: f64| -> i32 {
            const LIMIT: f64 = (1u64 << 30) as f64;
            let s = (v * SUB as f64).clamp(-LIMIT, LIMIT);
            let i = s as i64;
            let f = s - i as f64;
            (if f >= 0.5 {
                i + 1
            } else if f < -0.5 {
                i - 1
            } else {
                i
            }) as i32
        };
        let mut rng = bsp_core::internals::SplitMix(0xf1_0a7);
        let mut vals = vec![
            0.0,
            -0.0,
            1.5 / 256.0,
            -1.5 / 256.0,
            2.5 / 256.0,
            -2.5 / 256.0,
        ];
        vals.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300]);
        for _ in 0..100_000 {
            let k = rng.below(1 << 24) as f64 - (1 << 23) as f64;
            // on and near halves, and anywhere
            vals.push((k + 0.5) / 256.0);
            vals.push((k + 0.5 + (rng.below(3) as f64 - 1.0) * 1e-9) / 256.0);
            vals.push(((rng.next_u64() >> 24) as f64 - (1u64 << 39) as f64) * 1e-5);
        }
        for v in vals {
            assert_eq!(to_fixed(v), old(v), "{v:e}");
        }
        assert_eq!(to_fixed(2.5 / 256.0), 3);
        assert_eq!(to_fixed(-2.5 / 256.0), -2);
    }

    #[test]
    fn clip_bounds_agree_with_the_clip_planes() {
        // the bounds' tests against n · c + d >= 0, on points on, near and
        // off every plane of a perspective and an orthographic view
        let cam = Camera::look_at(
            DVec3::new(1.0, -5.0, 2.0),
            DVec3::ZERO,
            DVec3::Z,
            50.0,
            64,
            40,
        )
        .unwrap()
        .with_near(0.25);
        let mut ortho = cam.view.clone();
        ortho.kind = Kind::Orthographic { scale: 0.01 };
        let ortho = ortho.ready();
        let mut rng = bsp_core::internals::SplitMix(0xb0_0d5);
        for view in [&cam.view, &ortho] {
            let planes = view.clip_planes();
            let bounds = Bounds::of(view, &planes);
            let mut tested = [0usize; 2];
            for _ in 0..50_000 {
                let r = |rng: &mut bsp_core::internals::SplitMix| {
                    (rng.below(1 << 20) as f64 - (1 << 19) as f64) / 1024.0
                };
                let mut c = DVec3::new(r(&mut rng), r(&mut rng), r(&mut rng));
                // move some points exactly onto a plane
                match rng.below(4) {
                    0 => c.z = 0.25,
                    1 => {
                        if let Bounds::Pyramid { gx, .. } = bounds {
                            c.x = gx * c.z
                        } else if let Bounds::Box { hx, .. } = bounds {
                            c.x = -hx
                        }
                    }
                    2 => {
                        if let Bounds::Pyramid { gy, .. } = bounds {
                            c.y = -(gy * c.z)
                        } else if let Bounds::Box { hy, .. } = bounds {
                            c.y = hy
                        }
                    }
                    _ => {}
                }
                let want = planes.iter().all(|(n, d)| n.dot(c) + d >= 0.0);
                assert_eq!(bounds.inside(c), want, "{c:?}");
                tested[want as usize] += 1;
            }
            assert!(tested[0] > 1000 && tested[1] > 1000, "{tested:?}");
        }
    }

    #[test]
    fn shared_vertices_project_as_each_corner_does() {
        // a polygon projected from its shared vertices' points, against
        // projected corner by corner, in perspective views from outside
        // and from inside the scene (polygons cut by the near plane and
        // the guard band) and in a sun's orthographic view
        let mut compared = 0;
        for (scene, _, cams) in crate::testing::scenes() {
            let mut views: Vec<View> = cams.iter().map(|c| c.view.clone()).collect();
            let inside = Camera::look_at(
                DVec3::new(0.0, -0.5, 1.0),
                DVec3::new(3.0, 1.0, 0.5),
                DVec3::Z,
                120.0,
                80,
                60,
            )
            .unwrap()
            .with_near(0.3);
            views.push(inside.view.clone());
            let mut ortho = inside.view.clone();
            ortho.kind = Kind::Orthographic { scale: 0.05 };
            views.push(ortho.ready());
            for view in &views {
                let proj = Projector::new(view);
                let mut corners = Corners::default();
                corners.compute(&scene, &proj);
                let (mut a, mut b) = (Screen::new(), Screen::new());
                let mut sc = (Vec::new(), Vec::new());
                for i in 0..scene.len() {
                    let (n, d) = scene.plane[i];
                    if let Some(k) = view.coeffs(n, d) {
                        proj.add_prim(&scene, i, &corners, k, &mut a, &mut sc);
                        proj.add([scene.prim(i)], k, i as u32, &mut b, &mut sc);
                    }
                }
                assert_eq!(
                    (&a.pts, &a.ring_start, &a.poly_ring, &a.rows, &a.cols, &a.id),
                    (&b.pts, &b.ring_start, &b.poly_ring, &b.rows, &b.cols, &b.id)
                );
                compared += a.len();
                assert!(corners.fixed.iter().any(Option::is_some));
            }
            assert!(views.iter().any(|v| {
                let mut c = Corners::default();
                c.compute(&scene, &Projector::new(v));
                c.fixed.iter().any(Option::is_none)
            }));
        }
        assert!(compared > 100, "{compared}");
    }

    #[test]
    fn concatenated_parts_are_the_whole() {
        // a scene's polygons projected into one screen, and into parts
        // (one of them empty) put together again
        let (scene, _, cams) = crate::testing::scenes().swap_remove(0);
        let view = &cams[0].view;
        let proj = Projector::new(view);
        let mut sc = (Vec::new(), Vec::new());
        let add = |i: usize, out: &mut Screen, sc: &mut (Vec<DVec3>, Vec<DVec3>)| {
            let (n, d) = scene.plane[i];
            if let Some(k) = view.coeffs(n, d) {
                proj.add([scene.prim(i)], k, i as u32, out, sc);
            }
        };
        let mut whole = Screen::new();
        for i in 0..scene.len() {
            add(i, &mut whole, &mut sc);
        }
        let mut parts = vec![Screen::new(), Screen::new(), Screen::new(), Screen::new()];
        let cut = [0, 5, 5, 11, scene.len()];
        for (k, part) in parts.iter_mut().enumerate() {
            for i in cut[k]..cut[k + 1] {
                add(i, part, &mut sc);
            }
        }
        // into buffers of another size, and into the same ones again
        let mut joined = Screen::new();
        joined.pts = vec![[7, 7]; 3];
        for _ in 0..2 {
            joined.concat(&parts);
            assert_eq!(
                (
                    &joined.pts,
                    &joined.ring_start,
                    &joined.poly_ring,
                    &joined.rows
                ),
                (&whole.pts, &whole.ring_start, &whole.poly_ring, &whole.rows)
            );
            assert_eq!(
                (&joined.cols, &joined.coeffs, &joined.id),
                (&whole.cols, &whole.coeffs, &whole.id)
            );
        }
        assert!(whole.len() > 10);
    }

    #[test]
    fn bins_by_runs_list_each_band_in_polygon_order() {
        // random row ranges binned by runs of a few polygons (and by one
        // run) against a direct count: every band lists exactly the
        // polygons reaching it, in polygon order
        let mut rng = bsp_core::internals::SplitMix(0xb1_25);
        let height = 100u32;
        let mut s = Screen::new();
        for _ in 0..500 {
            let r0 = rng.below(height as usize) as i32;
            let r1 = r0 + 1 + rng.below((height as i32 - r0) as usize) as i32;
            s.rows.push((r0, r1));
        }
        let bands = (height as usize).div_ceil(BAND);
        let mut bins = Bins::default();
        let mut buf = Vec::new();
        for run in [7, 64, 499, 500, BIN_RUN] {
            bins.rebuild_by(&s, height, run);
            assert_eq!(bins.runs.len(), 500usize.div_ceil(run));
            for b in 0..bands {
                let want: Vec<u32> = (0..500u32)
                    .filter(|&i| {
                        let (r0, r1) = s.rows[i as usize];
                        (r0 as usize) < (b + 1) * BAND && r1 as usize > b * BAND
                    })
                    .collect();
                assert!(!want.is_empty());
                assert_eq!(bins.band(b, &mut buf), want, "run {run}, band {b}");
            }
        }
        // fewer polygons in the same buffers: no run is left from before
        s.rows.truncate(3);
        bins.rebuild_by(&s, height, 7);
        let all: usize = (0..bands).map(|b| bins.band(b, &mut buf).len()).sum();
        let direct: usize = s.rows[..3]
            .iter()
            .map(|&(r0, r1)| (r1 as usize - 1) / BAND + 1 - r0 as usize / BAND)
            .sum();
        assert_eq!(all, direct);
    }

    #[test]
    fn first_rows_by_shifting() {
        let ceil_div = |a: i64, b: i64| a.div_euclid(b) + (a.rem_euclid(b) != 0) as i64;
        for y in (-3000..3000).chain([i32::MIN as i64, i32::MAX as i64, -(1 << 40), 1 << 40]) {
            assert_eq!(first_row(y), ceil_div(y - HALF, SUB), "{y}");
        }
    }

    #[test]
    fn top_left_rule() {
        // a square whose sides run through pixel centres: the top and left
        // sides are in, the bottom and right ones out
        let sq = vec![fx(2.5, 2.5), fx(5.5, 2.5), fx(5.5, 5.5), fx(2.5, 5.5)];
        let cov = coverage(std::slice::from_ref(&sq), 8, 8);
        let covered: Vec<(usize, usize)> = (0..64)
            .filter(|&i| cov[i] == 1)
            .map(|i| (i % 8, i / 8))
            .collect();
        let want: Vec<(usize, usize)> = (2..5).flat_map(|y| (2..5).map(move |x| (x, y))).collect();
        assert_eq!(covered, want);
        // the same square the other way round covers the same pixels
        let rev: Vec<[i32; 2]> = sq.into_iter().rev().collect();
        assert_eq!(coverage(&[rev], 8, 8), cov);
    }

    #[test]
    fn holes_are_left_out() {
        let outer = vec![fx(0.0, 0.0), fx(10.0, 0.0), fx(10.0, 10.0), fx(0.0, 10.0)];
        let hole = vec![fx(3.0, 3.0), fx(3.0, 7.0), fx(7.0, 7.0), fx(7.0, 3.0)];
        let mut edges = Vec::new();
        for p in [&outer, &hole] {
            for k in 0..p.len() {
                if let Some(e) = Edge::new(p[k], p[(k + 1) % p.len()]) {
                    edges.push(e);
                }
            }
        }
        let mut n = 0;
        fill(&mut edges, 0..10, 10, &mut |_, xs| n += xs.end - xs.start);
        assert_eq!(n, 100 - 16);
    }

    #[test]
    fn clipping_shares_cut_points() {
        // two triangles sharing an edge that crosses the near plane: their
        // clipped, projected edges coincide and they tile without overlap
        let cam = Camera::look_at(
            DVec3::new(0.0, -1.0, 0.3),
            DVec3::new(0.0, 5.0, 0.0),
            DVec3::Z,
            70.0,
            32,
            32,
        )
        .unwrap()
        .with_near(0.5);
        let (a, b) = (DVec3::new(-0.2, -3.0, 0.0), DVec3::new(0.3, 6.0, 0.0));
        let t1 = [a, b, DVec3::new(-4.0, 2.0, 0.0)];
        let t2 = [b, a, DVec3::new(4.0, 1.0, 0.0)];
        let quad_cov = {
            let s = project_all(&cam.view, 2, |i, p, out, sc| {
                let t: &[DVec3] = if i == 0 { &t1 } else { &t2 };
                p.add([t], [0.0; 3], i as u32, out, sc);
            });
            let mut cov = vec![0u32; 32 * 32];
            let mut e = Vec::new();
            for i in 0..s.len() {
                s.spans(i, 0..32, 32, &mut e, |y, xs| {
                    for x in xs {
                        cov[(y * 32 + x) as usize] += 1;
                    }
                });
            }
            cov
        };
        assert!(quad_cov.iter().all(|&c| c <= 1));
        assert!(quad_cov.iter().filter(|&&c| c == 1).count() > 100);
    }
}
