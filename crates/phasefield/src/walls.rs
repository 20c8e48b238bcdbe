//! Static walls on the periodic lattice (docs/model.md §11.4): which nodes are solid, and the
//! wall field `w` that the wall terms of `mechanics` read.
//!
//! The wall field is 1 on solid nodes and decays as `e^{−d/ℓ_w}` outside, with `d` the
//! Euclidean distance from the node to the nearest solid node (periodic minimum image) and
//! `ℓ_w` the wall thickness. Its five-point Laplacian `∇²w` is computed once with it. The
//! lattice stays periodic: a wall is a region of the lattice, not a boundary of it, so
//! patches, neighbour tables and the centre of mass (by Fourier phase) are those of the
//! periodic lattice; a cell held off the walls never meets the seam of a channel or a box,
//! which lies inside the solid.

use crate::lattice::Lattice;

/// Where the field of a wall is cut to zero: `e^{−18.5} ≈ 9e-9` of its value at the wall.
const REACH_IN_THICKNESSES: f64 = 18.5;

/// The solid regions of the built-in geometries, on node coordinates `(x, y)`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum WallShape {
    /// Walls along x (the channel is periodic in x): the free rows are the `width` rows
    /// around the middle of the domain, `|y − (ly−1)/2| < width/2`.
    Channel {
        /// Free width in nodes (`ly − 2`: one solid row at each edge).
        width: f64,
    },
    /// Walls on all four sides: free where `|x − (lx−1)/2| < width[0]/2` and
    /// `|y − (ly−1)/2| < width[1]/2`.
    Box {
        /// Free widths along x and y in nodes.
        width: [f64; 2],
    },
    /// Free inside the ellipse `((x−cx)/a)² + ((y−cy)/b)² < 1` centred in the domain
    /// (`cx = (lx−1)/2`, `cy = (ly−1)/2`); a disc when `a = b`.
    Ellipse {
        /// Semi-axes `[a, b]` in nodes.
        semi_axes: [f64; 2],
    },
    /// A band across the domain, solid where `|x − (lx−1)/2| < width/2`: the wound of a
    /// wound-healing scene (removed when the activity switches on).
    Band {
        /// Width of the band in nodes.
        width: f64,
    },
    /// Solid where the mask is true, index `x * ly + y`.
    Mask(Vec<bool>),
}

impl WallShape {
    /// Whether each node is solid, index `x * ly + y`.
    ///
    /// # Panics
    /// For a [`WallShape::Mask`] that is not `lx * ly` long.
    pub fn solid(&self, lattice: Lattice) -> Vec<bool> {
        let (lx, ly) = (lattice.lx, lattice.ly);
        let (cx, cy) = ((lx as f64 - 1.0) / 2.0, (ly as f64 - 1.0) / 2.0);
        let at = |f: &dyn Fn(f64, f64) -> bool| -> Vec<bool> {
            (0..lx)
                .flat_map(|x| (0..ly).map(move |y| (x as f64 - cx, y as f64 - cy)))
                .map(|(dx, dy)| f(dx, dy))
                .collect()
        };
        match self {
            WallShape::Channel { width } => at(&|_, dy| dy.abs() >= width / 2.0),
            WallShape::Box { width } => {
                at(&|dx, dy| dx.abs() >= width[0] / 2.0 || dy.abs() >= width[1] / 2.0)
            }
            WallShape::Ellipse { semi_axes: [a, b] } => {
                at(&|dx, dy| (dx / a).powi(2) + (dy / b).powi(2) >= 1.0)
            }
            WallShape::Band { width } => at(&|dx, _| dx.abs() < width / 2.0),
            WallShape::Mask(mask) => {
                assert_eq!(mask.len(), lattice.len(), "a wall mask holds every node");
                mask.clone()
            }
        }
    }
}

/// The wall field of a solid region: `w`, `∇²w` and the distance to the solid, per node
/// (index `x * ly + y`).
#[derive(Debug, Clone, PartialEq)]
pub struct WallField {
    lattice: Lattice,
    thickness: f64,
    w: Vec<f64>,
    laplacian: Vec<f64>,
    distance: Vec<f64>,
    reach: f64,
}

impl WallField {
    /// The field of the solid nodes `solid` (index `x * ly + y`) with wall thickness
    /// `thickness` (`ℓ_w` of `w = e^{−d/ℓ_w}`, in nodes).
    ///
    /// Distances are exact (Euclidean, periodic) up to the field's reach, the larger of
    /// `18.5 ℓ_w` and `reach` (what the initial placement asks for), and that reach beyond;
    /// `w` is cut to zero past `18.5 ℓ_w`.
    ///
    /// # Panics
    /// If `solid` does not hold every node or `thickness` is not positive.
    pub fn new(lattice: Lattice, solid: &[bool], thickness: f64, reach: f64) -> Self {
        assert_eq!(
            solid.len(),
            lattice.len(),
            "the solid mask holds every node"
        );
        assert!(thickness > 0.0, "the wall thickness must be positive");
        let (lx, ly) = (lattice.lx, lattice.ly);
        let cut = (REACH_IN_THICKNESSES * thickness).max(reach);
        let half = lx.max(ly) as f64;
        let r = cut.min(half).ceil() as i64;
        let mut dist2 = vec![f64::INFINITY; lattice.len()];
        // Every free node's nearest solid node is on the solid's edge (a solid node with a
        // free neighbour), so stamping the disc of radius `r` around each edge node finds
        // every distance up to `r`.
        for x in 0..lx {
            for y in 0..ly {
                let k = x * ly + y;
                if !solid[k] {
                    continue;
                }
                dist2[k] = 0.0;
                let edge = [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)]
                    .iter()
                    .any(|&(a, b)| {
                        !solid[lattice
                            .index(lattice.wrap_x(x as i64 + a), lattice.wrap_y(y as i64 + b))]
                    });
                if !edge {
                    continue;
                }
                for a in -r..=r {
                    let xn = lattice.wrap_x(x as i64 + a);
                    for b in -r..=r {
                        let d2 = (a * a + b * b) as f64;
                        let kn = lattice.index(xn, lattice.wrap_y(y as i64 + b));
                        if d2 < dist2[kn] {
                            dist2[kn] = d2;
                        }
                    }
                }
            }
        }
        let w_cut = REACH_IN_THICKNESSES * thickness;
        let distance: Vec<f64> = dist2.iter().map(|d2| d2.sqrt()).collect();
        let w: Vec<f64> = distance
            .iter()
            .map(|&d| {
                if d == 0.0 {
                    1.0
                } else if d > w_cut {
                    0.0
                } else {
                    (-d / thickness).exp()
                }
            })
            .collect();
        let laplacian = (0..lattice.len())
            .map(|k| {
                let (x, y) = (k / ly, k % ly);
                let at = |a: i64, b: i64| {
                    w[lattice.index(lattice.wrap_x(x as i64 + a), lattice.wrap_y(y as i64 + b))]
                };
                at(1, 0) + at(-1, 0) + at(0, 1) + at(0, -1) - 4.0 * w[k]
            })
            .collect();
        Self {
            lattice,
            thickness,
            w,
            laplacian,
            distance,
            reach: r as f64,
        }
    }

    /// The field of a built-in geometry ([`WallField::new`] of [`WallShape::solid`]).
    pub fn of_shape(lattice: Lattice, shape: &WallShape, thickness: f64, reach: f64) -> Self {
        Self::new(lattice, &shape.solid(lattice), thickness, reach)
    }

    /// The lattice.
    pub fn lattice(&self) -> Lattice {
        self.lattice
    }

    /// The wall thickness `ℓ_w`.
    pub fn thickness(&self) -> f64 {
        self.thickness
    }

    /// `w` at every node (index `x * ly + y`).
    pub fn w(&self) -> &[f64] {
        &self.w
    }

    /// The five-point Laplacian `∇²w` at every node.
    pub fn laplacian(&self) -> &[f64] {
        &self.laplacian
    }

    /// The distance from each node to the nearest solid node: 0 on the solid, exact up to
    /// [`WallField::reach`], infinite beyond it.
    pub fn distance(&self) -> &[f64] {
        &self.distance
    }

    /// How far from the solid distances are exact, in nodes.
    pub fn reach(&self) -> f64 {
        self.reach
    }

    /// Whether node `k` is solid.
    pub fn is_solid(&self, k: usize) -> bool {
        self.distance[k] == 0.0
    }

    /// The distance from point `p` to the solid, at the node nearest to it.
    pub fn distance_at(&self, p: [f64; 2]) -> f64 {
        let l = self.lattice;
        let x = l.wrap_x(p[0].round() as i64);
        let y = l.wrap_y(p[1].round() as i64);
        self.distance[l.index(x, y)]
    }

    /// The number of free (not solid) nodes.
    pub fn free_nodes(&self) -> usize {
        self.distance.iter().filter(|&&d| d > 0.0).count()
    }

    /// Bytes of heap memory held.
    pub fn heap_bytes(&self) -> usize {
        (self.w.capacity() + self.laplacian.capacity() + self.distance.capacity())
            * std::mem::size_of::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A channel's field is the reference code's `e^{−y/ℓ}` from the wall row, to round-off,
    /// and its Laplacian is the second difference of that profile.
    #[test]
    fn a_channel_field_decays_exponentially_from_its_rows() {
        let l = Lattice::new(8, 40);
        let f = WallField::of_shape(l, &WallShape::Channel { width: 38.0 }, 1.5, 0.0);
        for y in 0..40usize {
            let d = y.min(39 - y) as f64;
            let expected = (-d / 1.5).exp();
            let k = l.index(3, y);
            assert!((f.w()[k] - expected).abs() < 1e-15, "y {y}");
            assert_eq!(f.is_solid(k), d == 0.0);
        }
        let k = l.index(5, 4);
        let second = (-3.0f64 / 1.5).exp() + (-5.0f64 / 1.5).exp() - 2.0 * (-4.0f64 / 1.5).exp();
        assert!((f.laplacian()[k] - second).abs() < 1e-15);
        assert_eq!(f.free_nodes(), 8 * 38);
    }

    /// Distances are Euclidean and periodic: a single solid node at the corner is at distance
    /// `√(a² + b²)` from `(a, b)` and from `(lx − a, ly − b)`.
    #[test]
    fn distances_are_periodic_and_euclidean() {
        let l = Lattice::new(30, 20);
        let mut solid = vec![false; l.len()];
        solid[l.index(0, 0)] = true;
        let f = WallField::new(l, &solid, 1.0, 0.0);
        for (a, b) in [(3usize, 4usize), (5, 2), (1, 1)] {
            let d = ((a * a + b * b) as f64).sqrt();
            assert_eq!(f.distance()[l.index(a, b)], d);
            assert_eq!(f.distance()[l.index(30 - a, 20 - b)], d);
        }
        assert_eq!(f.distance_at([2.6, 4.4]), 5.0);
    }

    /// A disc of radius 10: the nodes inside are free, the field is 1 outside it, and the
    /// free area is the disc's within its perimeter.
    #[test]
    fn an_ellipse_is_free_inside() {
        let l = Lattice::new(40, 40);
        let f = WallField::of_shape(
            l,
            &WallShape::Ellipse {
                semi_axes: [10.0, 10.0],
            },
            1.0,
            0.0,
        );
        let area = std::f64::consts::PI * 100.0;
        let free = f.free_nodes() as f64;
        assert!(
            (free - area).abs() < 2.0 * std::f64::consts::PI * 10.0,
            "{free}"
        );
        assert!(!f.is_solid(l.index(20, 20)) && f.is_solid(l.index(0, 0)));
        assert_eq!(f.w()[l.index(0, 0)], 1.0);
    }
}
