//! Making conflicting views agree by moving their images (`--optimize
//! --deform`): the paper's outer loop, an as-rigid-as-possible (ARAP)
//! deformation of each image that misses shadow.
//!
//! An image is covered by a grid of triangles (64 cells along its longer
//! side, none smaller than a pixel). The deformation moves the grid's
//! vertices so that each triangle moves as a rigid body as nearly as it
//! can (the local/global iteration of Sorkine and Alexa's ARAP: each
//! triangle's best rotation, then one sparse linear system for every
//! vertex), while soft constraints pull on it: the centre of each wanted
//! pixel the hull shadows (achieved) stays where it is, and the centre of
//! each wanted pixel it misses moves, by [`STEP`] pixels at most, toward
//! the nearest pixel the other views allow (the shadow of their hull). So
//! a part of the image that the other views forbid is moved, as a whole,
//! toward where they allow it, rather than answered by far thin lines in
//! the other images. The image is then sampled back through the moved
//! triangles (each pixel of the new image takes the pixel of the old one
//! that its centre came from), and the hull made again; the caller keeps
//! a round only if the views then miss less.
//!
//! The system's matrix is the same in every iteration of one deformation,
//! so it is factored once (Cholesky, by `rsparse`, a maintained port of
//! `CSparse`) and each iteration solves two right-hand sides (x and y).

use glam::DVec2;

use super::region::Mask;

/// Local/global iterations of one deformation.
const ITERATIONS: usize = 24;
/// Cells along the image's longer side.
const CELLS: f64 = 64.0;
/// The weight of all of one cell's pixel constraints together, against
/// the rigidity of its two triangles.
const PULL: f64 = 0.25;
/// How far (in pixels) a missed pixel is pulled in one deformation: the
/// images move in steps, the hull checked after each.
const STEP: f64 = 16.0;

/// How one view's image was moved.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Deformation {
    /// The largest distance of a wanted pixel from where its content was
    /// in the image as given, in pixels.
    pub max_displacement: f64,
    /// The mean of that distance over the image's wanted pixels.
    pub mean_displacement: f64,
}

/// A view's image while it is deformed: its mask, and for each pixel,
/// where (in the image as given, pixel units) its content came from.
#[derive(Clone, Debug)]
pub(crate) struct Moved {
    pub(crate) mask: Mask,
    origin: Vec<DVec2>,
}

impl Moved {
    /// The image as given: every pixel where it is.
    pub(crate) fn new(mask: &Mask) -> Moved {
        let w = mask.width as usize;
        let origin = (0..mask.wanted.len())
            .map(|p| centre(p % w, p / w))
            .collect();
        Moved {
            mask: mask.clone(),
            origin,
        }
    }

    /// How far the wanted pixels are from where their content was.
    pub(crate) fn deformation(&self) -> Deformation {
        let w = self.mask.width as usize;
        let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0usize);
        for (p, _) in self.mask.wanted.iter().enumerate().filter(|(_, w)| **w) {
            let d = centre(p % w, p / w).distance(self.origin[p]);
            max = max.max(d);
            sum += d;
            n += 1;
        }
        Deformation {
            max_displacement: max,
            mean_displacement: if n == 0 { 0.0 } else { sum / n as f64 },
        }
    }

    /// The image deformed as rigidly as possible so that its wanted pixels
    /// the hull misses (`coverage` below half) move toward the nearest
    /// pixels the other views allow (`allowed`: the shadow of their hull),
    /// and those the hull shadows stay. `None` when nothing is missed,
    /// nothing is allowed, or the image would lose every wanted pixel.
    pub(crate) fn deformed(&self, coverage: &[f32], allowed: &[bool]) -> Option<Moved> {
        let targets = targets(&self.mask, coverage, allowed)?;
        let grid = Grid::over(self.mask.width, self.mask.height);
        let moved = grid.solve(&targets)?;
        let out = self.resampled(&grid, &moved);
        out.mask.wanted.contains(&true).then_some(out)
    }

    /// The image sampled back through the grid's triangles moved to
    /// `moved`: each pixel whose centre a moved triangle covers takes the
    /// pixel of the old image its centre came from.
    fn resampled(&self, grid: &Grid, moved: &[DVec2]) -> Moved {
        let (w, h) = (self.mask.width as usize, self.mask.height as usize);
        let mut out = Moved {
            mask: Mask {
                width: self.mask.width,
                height: self.mask.height,
                wanted: vec![false; w * h],
            },
            origin: (0..w * h).map(|p| centre(p % w, p / w)).collect(),
        };
        for t in &grid.triangles {
            let d = t.map(|v| moved[v]);
            let r = t.map(|v| grid.rest[v]);
            let area = (d[1] - d[0]).perp_dot(d[2] - d[0]);
            if area == 0.0 {
                continue;
            }
            let lo = d[0].min(d[1]).min(d[2]);
            let hi = d[0].max(d[1]).max(d[2]);
            let (c0, c1) = (span(lo.x, w), span(hi.x + 1.0, w));
            let (r0, r1) = (span(lo.y, h), span(hi.y + 1.0, h));
            for row in r0..r1 {
                for col in c0..c1 {
                    let q = centre(col, row);
                    let b1 = (q - d[0]).perp_dot(d[2] - d[0]) / area;
                    let b2 = (d[1] - d[0]).perp_dot(q - d[0]) / area;
                    let b0 = 1.0 - b1 - b2;
                    if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 {
                        continue;
                    }
                    let from = r[0] * b0 + r[1] * b1 + r[2] * b2;
                    let (fc, fr) = (from.x.floor(), from.y.floor());
                    if fc < 0.0 || fr < 0.0 || fc >= w as f64 || fr >= h as f64 {
                        continue;
                    }
                    let src = fr as usize * w + fc as usize;
                    let p = row * w + col;
                    if self.mask.wanted[src] && !out.mask.wanted[p] {
                        out.mask.wanted[p] = true;
                        out.origin[p] = self.origin[src];
                    }
                }
            }
        }
        out
    }
}

/// The centre of pixel `(c, r)`.
fn centre(c: usize, r: usize) -> DVec2 {
    DVec2::new(c as f64 + 0.5, r as f64 + 0.5)
}

/// The pixel index `floor(x)`, clamped to `0..=n`: `span(lo)..span(hi +
/// 1)` holds every pixel whose centre lies in `[lo, hi]`.
fn span(x: f64, n: usize) -> usize {
    (x.floor().max(0.0) as usize).min(n)
}

/// The pixel constraints: each wanted pixel's centre and where it should
/// go: itself if the hull shadows it, else [`STEP`] pixels at most toward
/// the nearest `allowed` pixel's centre. `None` if no pixel is missed or
/// none is allowed.
fn targets(mask: &Mask, coverage: &[f32], allowed: &[bool]) -> Option<Vec<(DVec2, DVec2)>> {
    let (w, h) = (mask.width as usize, mask.height as usize);
    let achieved = |p: usize| coverage[p] >= 0.5;
    let missed = (0..w * h).any(|p| mask.wanted[p] && !achieved(p));
    if !missed || !allowed.contains(&true) {
        return None;
    }
    let near = nearest(allowed, w, h);
    let out = (0..w * h)
        .filter(|&p| mask.wanted[p])
        .map(|p| {
            let at = centre(p % w, p / w);
            if achieved(p) {
                return (at, at);
            }
            let d = centre(near[p] % w, near[p] / w) - at;
            (at, at + d * (STEP / d.length()).min(1.0))
        })
        .collect();
    Some(out)
}

/// For every pixel, a nearest `seed` pixel (Euclidean, by propagation
/// from the seeds over 8-neighbours, each pixel keeping the nearer of its
/// neighbours' seeds: exact but for rare ties far from the seeds).
fn nearest(seed: &[bool], w: usize, h: usize) -> Vec<usize> {
    let mut near = vec![usize::MAX; w * h];
    let mut queue = std::collections::VecDeque::new();
    for (p, _) in seed.iter().enumerate().filter(|(_, s)| **s) {
        near[p] = p;
        queue.push_back(p);
    }
    let d2 = |p: usize, q: usize| {
        let (dx, dy) = (
            (p % w) as i64 - (q % w) as i64,
            (p / w) as i64 - (q / w) as i64,
        );
        dx * dx + dy * dy
    };
    while let Some(p) = queue.pop_front() {
        let (c, r) = ((p % w) as i64, (p / w) as i64);
        for (dc, dr) in [
            (-1, 0),
            (1, 0),
            (0, -1),
            (0, 1),
            (-1, -1),
            (1, -1),
            (-1, 1),
            (1, 1),
        ] {
            let (nc, nr) = (c + dc, r + dr);
            if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                continue;
            }
            let q = nr as usize * w + nc as usize;
            let s = near[p];
            if near[q] == usize::MAX || d2(q, s) < d2(q, near[q]) {
                near[q] = s;
                queue.push_back(q);
            }
        }
    }
    near
}

/// A triangle grid over an image, in pixel units.
struct Grid {
    /// Vertices per row.
    nx: usize,
    /// The cell's size.
    step: DVec2,
    rest: Vec<DVec2>,
    triangles: Vec<[usize; 3]>,
}

impl Grid {
    fn over(width: u32, height: u32) -> Grid {
        let (w, h) = (f64::from(width), f64::from(height));
        // (no cell smaller than a pixel)
        let cells = |side: f64| (side * CELLS / w.max(h)).ceil().clamp(1.0, side) as usize;
        let (cx, cy) = (cells(w), cells(h));
        let step = DVec2::new(w / cx as f64, h / cy as f64);
        let nx = cx + 1;
        let rest = (0..=cy)
            .flat_map(|j| (0..=cx).map(move |i| DVec2::new(i as f64, j as f64) * step))
            .collect();
        let mut triangles = Vec::with_capacity(2 * cx * cy);
        for j in 0..cy {
            for i in 0..cx {
                let v = j * nx + i;
                triangles.push([v, v + 1, v + nx + 1]);
                triangles.push([v, v + nx + 1, v + nx]);
            }
        }
        Grid {
            nx,
            step,
            rest,
            triangles,
        }
    }

    /// The triangle holding point `p` (clamped into the grid) and `p`'s
    /// barycentric weights in it.
    fn locate(&self, p: DVec2) -> ([usize; 3], [f64; 3]) {
        let cx = self.nx - 1;
        let cy = self.rest.len() / self.nx - 1;
        let g = p / self.step;
        let i = (g.x.floor().max(0.0) as usize).min(cx - 1);
        let j = (g.y.floor().max(0.0) as usize).min(cy - 1);
        let (u, v) = (g.x - i as f64, g.y - j as f64);
        let t = 2 * (j * cx + i) + usize::from(v > u);
        let tri = self.triangles[t];
        let [a, b, c] = tri.map(|k| self.rest[k]);
        let area = (b - a).perp_dot(c - a);
        let wb = (p - a).perp_dot(c - a) / area;
        let wc = (b - a).perp_dot(p - a) / area;
        (tri, [1.0 - wb - wc, wb, wc])
    }

    /// The vertices' positions that minimise the triangles' departure
    /// from rigid motions plus the constraints' pull (`(from, to)` pairs
    /// of points): `None` if the system cannot be factored.
    fn solve(&self, constraints: &[(DVec2, DVec2)]) -> Option<Vec<DVec2>> {
        let n = self.rest.len();
        let mut entries: Vec<(usize, usize, f64)> = Vec::new();
        let mut add = |i: usize, j: usize, x: f64| entries.push((j, i, x));
        for t in &self.triangles {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                add(a, a, 1.0);
                add(b, b, 1.0);
                add(a, b, -1.0);
                add(b, a, -1.0);
            }
        }
        // a cell's pixels together weigh PULL
        let weight = PULL / (self.step.x * self.step.y);
        let mut fixed = vec![DVec2::ZERO; n];
        for &(from, to) in constraints {
            let (tri, b) = self.locate(from);
            for (x, &i) in b.iter().zip(&tri) {
                fixed[i] += to * (weight * x);
                for (y, &j) in b.iter().zip(&tri) {
                    add(i, j, weight * x * y);
                }
            }
        }
        let a = csc(n, entries);
        let mut symbolic = rsparse::schol(&a, 0);
        let factor = rsparse::chol(&a, &mut symbolic).ok()?;
        let solve = |rhs: &[f64]| -> Vec<f64> {
            let mut x = vec![0.0; n];
            let at = |k: usize| symbolic.pinv.as_ref().map_or(k, |p| p[k] as usize);
            for (k, &b) in rhs.iter().enumerate() {
                x[at(k)] = b;
            }
            rsparse::lsolve(&factor.l, &mut x);
            rsparse::ltsolve(&factor.l, &mut x);
            (0..n).map(|k| x[at(k)]).collect()
        };
        let mut pos = self.rest.clone();
        for _ in 0..ITERATIONS {
            let mut rhs = fixed.clone();
            for t in &self.triangles {
                let edges = [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
                let (mut s, mut c) = (0.0, 0.0);
                for &(i, j) in &edges {
                    let (e, f) = (self.rest[i] - self.rest[j], pos[i] - pos[j]);
                    s += e.perp_dot(f);
                    c += e.dot(f);
                }
                let turn = DVec2::new(c, s).try_normalize().unwrap_or(DVec2::X);
                for &(i, j) in &edges {
                    let r = turn.rotate(self.rest[i] - self.rest[j]);
                    rhs[i] += r;
                    rhs[j] -= r;
                }
            }
            let xs = solve(&rhs.iter().map(|v| v.x).collect::<Vec<_>>());
            let ys = solve(&rhs.iter().map(|v| v.y).collect::<Vec<_>>());
            pos = xs
                .into_iter()
                .zip(ys)
                .map(|(x, y)| DVec2::new(x, y))
                .collect();
            if !pos.iter().all(|p| p.is_finite()) {
                return None;
            }
        }
        Some(pos)
    }
}

/// The `n × n` matrix of `(column, row, value)` entries, duplicates
/// summed, in compressed columns.
fn csc(n: usize, mut entries: Vec<(usize, usize, f64)>) -> rsparse::data::Sprs<f64> {
    entries.sort_unstable_by_key(|&(c, r, _)| (c, r));
    let mut a = rsparse::data::Sprs::zeros(n, n, 0);
    let (mut rows, mut values, mut counts) = (Vec::new(), Vec::new(), vec![0isize; n + 1]);
    let mut last = None;
    for (c, r, x) in entries {
        if last == Some((c, r)) {
            *values.last_mut().expect("an entry") += x;
            continue;
        }
        last = Some((c, r));
        rows.push(r);
        values.push(x);
        counts[c + 1] += 1;
    }
    for c in 0..n {
        counts[c + 1] += counts[c];
    }
    a.nzmax = rows.len();
    (a.p, a.i, a.x) = (counts, rows, values);
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(n: u32, lo: u32, hi: u32) -> Mask {
        let wanted = (0..n * n)
            .map(|p| (lo..hi).contains(&(p % n)) && (lo..hi).contains(&(p / n)))
            .collect();
        Mask {
            width: n,
            height: n,
            wanted,
        }
    }

    fn worst(a: &[DVec2], b: &[DVec2]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f64::max)
    }

    #[test]
    fn rigid_motions_cost_nothing() {
        // constraints that ask for the identity, a shift, or a turn of
        // the whole grid get it back: those have no ARAP energy
        let g = Grid::over(40, 30);
        let points: Vec<DVec2> = (0..30)
            .flat_map(|r| (0..40).map(move |c| centre(c, r)))
            .step_by(7)
            .collect();
        let same: Vec<_> = points.iter().map(|&p| (p, p)).collect();
        assert!(worst(&g.solve(&same).unwrap(), &g.rest) < 1e-9);
        let by = DVec2::new(3.0, -1.5);
        let shifted: Vec<_> = points.iter().map(|&p| (p, p + by)).collect();
        let want: Vec<_> = g.rest.iter().map(|&p| p + by).collect();
        assert!(worst(&g.solve(&shifted).unwrap(), &want) < 1e-9);
        let (mid, turn) = (DVec2::new(20.0, 15.0), DVec2::from_angle(0.1));
        let spin = |p: DVec2| mid + turn.rotate(p - mid);
        let turned: Vec<_> = points.iter().map(|&p| (p, spin(p))).collect();
        let want: Vec<_> = g.rest.iter().map(|&p| spin(p)).collect();
        // (the local/global iteration nears a turn geometrically: within a
        // twentieth of a pixel of it, from 2.5 px away)
        let w = worst(&g.solve(&turned).unwrap(), &want);
        assert!(worst(&g.rest, &want) > 2.0 && w < 0.05, "{w}");
    }

    #[test]
    fn a_grid_is_never_finer_than_the_pixels() {
        let g = Grid::over(6, 3);
        assert_eq!((g.nx, g.rest.len(), g.triangles.len()), (7, 28, 36));
        // every pixel centre lies in the triangle it is located in
        for p in (0..3).flat_map(|r| (0..6).map(move |c| centre(c, r))) {
            let (tri, b) = g.locate(p);
            assert!(b.iter().all(|&x| (0.0..=1.0).contains(&x)), "{b:?}");
            let back = g.rest[tri[0]] * b[0] + g.rest[tri[1]] * b[1] + g.rest[tri[2]] * b[2];
            assert!(back.distance(p) < 1e-12);
        }
    }

    #[test]
    fn a_shifted_grid_shifts_the_image_and_says_how_far() {
        let m = Moved::new(&square(16, 4, 8));
        let g = Grid::over(16, 16);
        let moved: Vec<_> = g.rest.iter().map(|&p| p + DVec2::new(3.0, 0.0)).collect();
        let out = m.resampled(&g, &moved);
        assert_eq!(out.mask.wanted, square_at(16, 7, 11, 4, 8));
        let d = out.deformation();
        assert_eq!((d.max_displacement, d.mean_displacement), (3.0, 3.0));
        assert_eq!(m.deformation(), Deformation::default());
    }

    fn square_at(n: u32, c0: u32, c1: u32, r0: u32, r1: u32) -> Vec<bool> {
        (0..n * n)
            .map(|p| (c0..c1).contains(&(p % n)) && (r0..r1).contains(&(p / n)))
            .collect()
    }

    #[test]
    fn missed_pixels_move_toward_the_allowed_ones() {
        // an 8-wide square of which the hull gives the right half, the
        // other views allowing the columns 8..16: the left half moves
        // right, by at most its width, and the right half stays
        let m = Moved::new(&square(24, 4, 12));
        let columns = |p: usize, lo: usize, hi: usize| (lo..hi).contains(&(p % 24));
        let coverage: Vec<f32> = (0..576)
            .map(|p| f32::from(u8::from(columns(p, 8, 12))))
            .collect();
        let allowed: Vec<bool> = (0..576).map(|p| columns(p, 8, 16)).collect();
        let out = m.deformed(&coverage, &allowed).unwrap();
        let d = out.deformation();
        assert!(
            d.max_displacement >= 1.0 && d.max_displacement <= 4.5,
            "{d:?}"
        );
        let wanted = |c: usize, r: usize| out.mask.wanted[r * 24 + c];
        assert!((8..12).all(|c| (5..11).all(|r| wanted(c, r))));
        assert!(!wanted(4, 8) && !wanted(13, 8));
        // nothing missed, or nothing allowed: nothing to do
        assert!(m.deformed(&[1.0; 576], &allowed).is_none());
        assert!(m.deformed(&coverage, &[false; 576]).is_none());
    }

    #[test]
    fn duplicate_entries_are_summed() {
        let a = csc(2, vec![(0, 0, 1.0), (1, 1, 2.0), (0, 0, 3.0), (0, 1, -1.0)]);
        assert_eq!(
            (a.p.as_slice(), a.i.as_slice()),
            (&[0, 2, 3][..], &[0, 1, 1][..])
        );
        assert_eq!(a.x, [4.0, -1.0, 2.0]);
    }
}
