//! A study's scene cut into tiles, so that a run may shade part of the
//! faces with only the occluders that can hide the sun from them: less
//! work and memory a task when a scene is too big for one worker.
//!
//! The tiles split the box of the scene's grid coordinates along its two
//! longest axes into `per_side × per_side` equal cells; a face belongs to
//! the cell holding the centre of its box (half-open cells, so to exactly
//! one). A tile's run shades its faces with, for each sun, the faces whose
//! box meets the tile's faces' box swept toward the sun (exact, in
//! integers): every occluder that hides the sun from a point of the tile
//! does, so every fragment's class is the one the whole scene gives. The
//! fragments' partition (and so the last bits of an area) may differ from
//! an untiled run's; a tiled study is the same, bit for bit, wherever its
//! runs are made.

use bsp_core::{GridPoint, Point, Polygon};

/// Tile `index` (`0 .. per_side²`) of a study cut into `per_side ×
/// per_side` tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    /// Which tile, row after row.
    pub index: usize,
    /// Tiles along each of the two axes cut.
    pub per_side: usize,
}

impl Tile {
    /// Every tile of a study cut into `per_side × per_side`, in order.
    pub fn all(per_side: usize) -> impl Iterator<Item = Tile> {
        (0..per_side * per_side).map(move |index| Tile { index, per_side })
    }
}

/// A tile's part of a scene's imported polygons.
pub(crate) struct TileFaces {
    /// The tile's polygons (indices into the scene's, in order).
    pub polys: Vec<usize>,
    /// The faces they are of, ascending, each once.
    pub faces: Vec<u32>,
    /// The least and greatest grid coordinates of their vertices (`None`
    /// for a tile with no face).
    pub bounds: Option<[GridPoint; 2]>,
}

/// The grid box of a polygon with grid vertices (an imported face's);
/// `None` for a polygon with an implicit vertex.
fn grid_box(p: &Polygon) -> Option<[GridPoint; 2]> {
    let mut b: Option<[GridPoint; 2]> = None;
    for v in p.vertices() {
        let Point::Grid(g) = v else {
            return None;
        };
        let [lo, hi] = b.get_or_insert([*g, *g]);
        for k in 0..3 {
            lo[k] = lo[k].min(g[k]);
            hi[k] = hi[k].max(g[k]);
        }
    }
    b
}

/// The least and greatest grid coordinates of the polygons' vertices
/// (which are grid points: imported faces), `None` for no polygon or a
/// polygon with an implicit vertex.
pub(crate) fn grid_bounds(polys: &[Polygon]) -> Option<[GridPoint; 2]> {
    let boxes: Vec<[GridPoint; 2]> = polys.iter().map(grid_box).collect::<Option<_>>()?;
    hull(&boxes)
}

/// The smallest box holding all of `boxes` (`None` for none).
fn hull(boxes: &[[GridPoint; 2]]) -> Option<[GridPoint; 2]> {
    boxes.iter().fold(None, |a, b| Some(join(a, *b)))
}

/// The smallest box holding both.
fn join(a: Option<[GridPoint; 2]>, b: [GridPoint; 2]) -> [GridPoint; 2] {
    let Some([mut lo, mut hi]) = a else {
        return b;
    };
    for k in 0..3 {
        lo[k] = lo[k].min(b[0][k]);
        hi[k] = hi[k].max(b[1][k]);
    }
    [lo, hi]
}

/// A scene's imported polygons cut into `per_side × per_side` tiles,
/// once for all the runs of a study: each polygon's box and each tile's
/// polygons.
pub(crate) struct TileIndex {
    /// The tiles along each axis.
    pub per_side: usize,
    /// Each polygon's grid box.
    pub boxes: Vec<[GridPoint; 2]>,
    /// The tiles, row after row.
    pub tiles: Vec<TileFaces>,
}

impl TileIndex {
    /// The tiles of the scene's imported `polys` (grid vertices; polygons
    /// of one face consecutive, as imported). `None` if a polygon has an
    /// implicit vertex, or for no tiles (`per_side` 0, or too many).
    pub(crate) fn new(polys: &[Polygon], per_side: usize) -> Option<TileIndex> {
        let count = per_side.checked_mul(per_side).filter(|&c| c > 0)?;
        let boxes: Vec<[GridPoint; 2]> = polys.iter().map(grid_box).collect::<Option<_>>()?;
        let empty = || TileFaces {
            polys: Vec::new(),
            faces: Vec::new(),
            bounds: None,
        };
        let mut tiles: Vec<TileFaces> = (0..count).map(|_| empty()).collect();
        let Some([lo, hi]) = hull(&boxes) else {
            return Some(TileIndex {
                per_side,
                boxes,
                tiles,
            });
        };
        // the two longest axes, the lower first where equal
        let mut axes = [0usize, 1, 2];
        axes.sort_by_key(|&k| std::cmp::Reverse(hi[k] as i64 - lo[k] as i64));
        let n = per_side as i128;
        let tile_of = |[flo, fhi]: [GridPoint; 2]| {
            let [a, b] = [axes[0], axes[1]].map(|k| {
                // twice the centre, from twice the low corner, in cells of
                // twice the extent (plus one: the top lies in the last cell)
                let c2 = flo[k] as i128 + fhi[k] as i128 - 2 * lo[k] as i128;
                c2 * n / (2 * (hi[k] as i128 - lo[k] as i128) + 1)
            });
            (a * n + b) as usize
        };
        // each face's box, over its consecutive polygons, then its tile
        let mut start = 0;
        while start < polys.len() {
            let face = polys[start].tag();
            let end = start
                + polys[start..]
                    .iter()
                    .take_while(|p| p.tag() == face)
                    .count();
            let fb = hull(&boxes[start..end]).expect("a face's polygons");
            let t = &mut tiles[tile_of(fb)];
            t.polys.extend(start..end);
            t.faces.push(face);
            t.bounds = Some(join(t.bounds, fb));
            start = end;
        }
        for t in &mut tiles {
            t.faces.sort_unstable();
            t.faces.dedup();
        }
        Some(TileIndex {
            per_side,
            boxes,
            tiles,
        })
    }

    /// Tile `tile` of this index; `None` if it is not one of its tiles.
    pub(crate) fn get(&self, tile: Tile) -> Option<&TileFaces> {
        (tile.per_side == self.per_side).then(|| self.tiles.get(tile.index))?
    }
}

/// Whether `light` may be hidden from a point of the box `reach` by
/// something in the box `face`: for a sun of direction `d` (toward it),
/// whether `face` meets `reach + t d` for some `t >= 0`, exactly; for a
/// point light, whether `face` meets the box of `reach` and the light.
pub(crate) fn may_shade(light: &svbsp::Light, reach: [GridPoint; 2], face: [GridPoint; 2]) -> bool {
    let [rl, rh] = reach;
    let [fl, fh] = face;
    match *light {
        svbsp::Light::Point(l) => {
            (0..3).all(|k| fl[k] <= rh[k].max(l[k]) && fh[k] >= rl[k].min(l[k]))
        }
        svbsp::Light::Directional(d) => {
            // per axis, fl - rh <= t d <= fh - rl: bounds on t as
            // fractions with positive denominators (t >= 0 the first
            // lower one; an axis along which the sun does not move gives
            // none, or no t at all)
            let (mut lower, mut upper) = ([(0i128, 1i128); 4], [(0i128, 1i128); 3]);
            let (mut nl, mut nu) = (1, 0);
            for k in 0..3 {
                let (a, b) = (fl[k] as i128 - rh[k] as i128, fh[k] as i128 - rl[k] as i128);
                let dk = d[k] as i128;
                let (lo, hi) = match dk.signum() {
                    0 if a > 0 || b < 0 => return false,
                    0 => continue,
                    1 => ((a, dk), (b, dk)),
                    _ => ((-b, -dk), (-a, -dk)),
                };
                lower[nl] = lo;
                upper[nu] = hi;
                (nl, nu) = (nl + 1, nu + 1);
            }
            // |numerators| < 2^33, denominators < 2^31: no overflow
            lower[..nl]
                .iter()
                .all(|&(p, q)| upper[..nu].iter().all(|&(r, s)| p * s <= r * q))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: i32, y: i32, z: i32, tag: u32) -> Polygon {
        let pts = [[x, y, z], [x + 2, y, z], [x + 2, y + 2, z], [x, y + 2, z]];
        Polygon::from_grid_points(&pts, tag).unwrap()
    }

    /// Every face in exactly one tile, by the centre of its box.
    #[test]
    fn each_face_lies_in_one_tile() {
        let polys: Vec<Polygon> = (0..10)
            .flat_map(|i| (0..7).map(move |j| (i, j)))
            .map(|(i, j)| square(4 * i, 5 * j, (i * j) % 3, (i * 7 + j) as u32))
            .collect();
        for per_side in 1..5 {
            let mut seen = vec![0; polys.len()];
            let index = TileIndex::new(&polys, per_side).unwrap();
            for t in Tile::all(per_side) {
                let tf = index.get(t).unwrap();
                assert_eq!(tf.polys.len(), tf.faces.len());
                for &f in &tf.faces {
                    seen[f as usize] += 1;
                }
                if let Some([lo, hi]) = tf.bounds {
                    for &p in &tf.polys {
                        let [a, b] = grid_box(&polys[p]).unwrap();
                        assert!((0..3).all(|k| lo[k] <= a[k] && b[k] <= hi[k]));
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{per_side}: {seen:?}");
        }
        // x is the longest axis (36 + 2), then y (30 + 2): tile 1 of 2 × 2
        // is x low, y high
        let index = TileIndex::new(&polys, 2).unwrap();
        let t = index
            .get(Tile {
                index: 1,
                per_side: 2,
            })
            .unwrap();
        let [lo, hi] = t.bounds.unwrap();
        assert!(hi[0] <= 20 && lo[1] >= 15, "{lo:?} {hi:?}");
        assert!(
            index
                .get(Tile {
                    index: 4,
                    per_side: 2
                })
                .is_none()
        );
        assert!(
            index
                .get(Tile {
                    index: 0,
                    per_side: 3
                })
                .is_none()
        );
        assert!(TileIndex::new(&polys, 0).is_none());
    }

    /// The sweep test against sampling the sweep densely.
    #[test]
    fn sweep_test_agrees_with_sampling() {
        let reach = [[0, 0, 0], [4, 4, 1]];
        let suns = [
            [1, 0, 2],
            [-3, 1, 1],
            [0, 0, 1],
            [2, -2, 5],
            [0, 1, 0],
            [-1, -1, -1],
        ];
        for d in suns {
            let light = svbsp::Light::Directional(d);
            for (x, y, z) in (-12..16)
                .flat_map(|x| (-12..16).flat_map(move |y| (-3..12).map(move |z| (x, y, z))))
            {
                let face = [[x, y, z], [x + 1, y + 2, z]];
                // t in steps of 1/64 up to 20, points of reach on its
                // lattice of halves: a hit proves the sweep meets the face
                let hit = (0..=1280).any(|t| {
                    let t = t as f64 / 64.0;
                    (0..3).all(|k| {
                        let (lo, hi) = (
                            reach[0][k] as f64 + t * d[k] as f64,
                            reach[1][k] as f64 + t * d[k] as f64,
                        );
                        lo <= face[1][k] as f64 && hi >= face[0][k] as f64
                    })
                });
                let exact = may_shade(&light, reach, face);
                assert!(
                    exact || !hit,
                    "sun {d:?}, face {face:?}: sampled hit missed"
                );
                // exactly: where the sweep meets the face, it does at the
                // least t it may, 0 or where an axis's overlap begins
                let mut starts = vec![(0i64, 1i64)];
                for k in 0..3 {
                    let dk = d[k] as i64;
                    for e in [face[0][k] - reach[1][k], face[1][k] - reach[0][k]] {
                        if dk != 0 && (e as i64) * dk.signum() >= 0 {
                            starts.push(((e as i64) * dk.signum(), dk.abs()));
                        }
                    }
                }
                let at = |(p, q): (i64, i64)| {
                    (0..3).all(|k| {
                        let td = p * d[k] as i64;
                        q * (face[0][k] - reach[1][k]) as i64 <= td
                            && td <= q * (face[1][k] - reach[0][k]) as i64
                    })
                };
                assert_eq!(
                    exact,
                    starts.into_iter().any(at),
                    "sun {d:?}, face {face:?}"
                );
            }
        }
        // a point light: the box of the reach and the light
        let l = svbsp::Light::Point([10, 0, 0]);
        assert!(may_shade(&l, reach, [[8, 1, 0], [9, 2, 1]]));
        assert!(!may_shade(&l, reach, [[11, 1, 0], [12, 2, 1]]));
    }
}
