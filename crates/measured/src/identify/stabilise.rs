//! Model order and spurious modes (`docs/measured.md` 3.3, Eq. I7): candidates within the
//! damping bound, followed from one order to the next when they repeat; a track stable at
//! enough orders and of enough amplitude is a mode.

use faer::c64;

use super::era::{Candidate, Diagram};
use super::pole;

/// Stable: a candidate of the order below within this relative frequency difference ...
pub(crate) const STABLE_DF: f64 = 0.01;
/// ... this relative damping difference ...
pub(crate) const STABLE_DZETA: f64 = 0.25;
/// ... and at least this modal assurance criterion (Eq. I7).
pub(crate) const STABLE_MAC: f64 = 0.9;
/// A track whose amplitude is below this share of the largest track's is dropped.
pub(crate) const MIN_AMPLITUDE: f64 = 1e-3;

/// A mode found in the stabilisation diagram: the start of the fit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Start {
    /// Median frequency and damping ratio of the track, as a pole [1/s] (Eq. I2).
    pub s: c64,
    /// The number of orders at which the mode is stable.
    pub stable_orders: usize,
    /// Median amplitude of the track (weighted units, Eq. I5).
    pub amplitude: f64,
}

/// The modes of `diagram` (3.3): candidates with `0 < zeta < zeta_max` followed from each order
/// to the next (each linked to the candidate of the order below that it repeats most closely,
/// one to one), the tracks so formed joined where one mode's track was interrupted, and kept
/// when stable at `min_fraction` of the orders that can be (all but the first) and of amplitude
/// at least [`MIN_AMPLITUDE`] of the largest; ascending frequency.
pub(crate) fn modes(diagram: &Diagram, zeta_max: f64, min_fraction: f64) -> Vec<Start> {
    let tracks = join_interrupted(tracks(diagram, zeta_max));
    let possible = diagram.orders.len().saturating_sub(1).max(1);
    let mut starts: Vec<Start> = tracks
        .iter()
        .filter(|t| t.stable_orders() as f64 >= min_fraction * possible as f64)
        .map(Track::start)
        .collect();
    let largest = starts.iter().map(|s| s.amplitude).fold(0.0, f64::max);
    starts.retain(|s| s.amplitude >= MIN_AMPLITUDE * largest);
    starts.sort_by(|a, b| pole::frequency_hz(a.s).total_cmp(&pole::frequency_hz(b.s)));
    starts
}

/// A candidate followed over the orders: `(order index, candidate)`, ascending orders, each
/// member repeating the one before it except across a join.
#[derive(Debug, Clone)]
struct Track<'a> {
    members: Vec<(usize, &'a Candidate)>,
    /// Members that repeat the one of the order below (Eq. I7): the orders it is stable at.
    stable: usize,
}

impl Track<'_> {
    fn stable_orders(&self) -> usize {
        self.stable
    }

    fn median_of(&self, f: impl Fn(&Candidate) -> f64) -> f64 {
        median(self.members.iter().map(|m| f(m.1)).collect())
    }

    /// The start of the fit: the track's median frequency, ratio and amplitude.
    fn start(&self) -> Start {
        let f = self.median_of(|c| pole::frequency_hz(c.s));
        let z = self.median_of(|c| pole::damping_ratio(c.s));
        Start {
            s: pole::from_frequency(f, z),
            stable_orders: self.stable,
            amplitude: self.median_of(|c| c.amplitude),
        }
    }

    /// The shape of the member of the highest order.
    fn last_shape(&self) -> &[c64] {
        &self.members[self.members.len() - 1].1.shape
    }

    fn orders(&self) -> impl Iterator<Item = usize> + '_ {
        self.members.iter().map(|m| m.0)
    }
}

/// Whether a candidate's ratio lies within `(0, zeta_max)`.
fn admissible(c: &Candidate, zeta_max: f64) -> bool {
    let z = pole::damping_ratio(c.s);
    z > 0.0 && z < zeta_max
}

/// The modal assurance criterion of two shapes (Eq. I7).
pub(crate) fn mac(a: &[c64], b: &[c64]) -> f64 {
    let dot: c64 = a.iter().zip(b).map(|(x, y)| x.conj() * y).sum();
    let na: f64 = a.iter().map(|x| x.norm_sqr()).sum();
    let nb: f64 = b.iter().map(|x| x.norm_sqr()).sum();
    if na == 0.0 || nb == 0.0 {
        return 0.0;
    }
    dot.norm_sqr() / (na * nb)
}

/// Whether the pole `s` with shape `shape` repeats `(sp, shape_p)` within the stability
/// tolerances (3.3).
fn repeats(s: c64, shape: &[c64], sp: c64, shape_p: &[c64]) -> bool {
    let (f, fp) = (pole::frequency_hz(s), pole::frequency_hz(sp));
    let (z, zp) = (pole::damping_ratio(s), pole::damping_ratio(sp));
    (f - fp).abs() <= STABLE_DF * f && (z - zp).abs() <= STABLE_DZETA * z && mac(shape, shape_p) >= STABLE_MAC
}

/// The tracks of the admissible candidates: each candidate of order i continues the track of
/// the candidate of order i - 1 that it repeats most closely (relative pole distance), unless a
/// closer candidate of order i took that one; otherwise it starts a track.
fn tracks(diagram: &Diagram, zeta_max: f64) -> Vec<Track<'_>> {
    let mut tracks: Vec<Track> = Vec::new();
    // the track of each admissible candidate of the previous order, by its index there
    let mut previous: Vec<(usize, usize)> = Vec::new();
    for (i, candidates) in diagram.candidates.iter().enumerate() {
        let admitted: Vec<usize> = (0..candidates.len())
            .filter(|&k| admissible(&candidates[k], zeta_max))
            .collect();
        // (distance, this candidate, track it would continue)
        let mut links: Vec<(f64, usize, usize)> = Vec::new();
        for &k in &admitted {
            let c = &candidates[k];
            for &(kp, track) in &previous {
                let p = &diagram.candidates[i - 1][kp];
                if repeats(c.s, &c.shape, p.s, &p.shape) {
                    links.push(((c.s - p.s).norm() / c.s.norm(), k, track));
                }
            }
        }
        links.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut current: Vec<(usize, usize)> = Vec::new();
        let mut taken_track = vec![false; tracks.len()];
        for (_, k, track) in links {
            if taken_track[track] || current.iter().any(|&(kc, _)| kc == k) {
                continue;
            }
            taken_track[track] = true;
            tracks[track].members.push((i, &candidates[k]));
            tracks[track].stable += 1;
            current.push((k, track));
        }
        for &k in &admitted {
            if !current.iter().any(|&(kc, _)| kc == k) {
                tracks.push(Track {
                    members: vec![(i, &candidates[k])],
                    stable: 0,
                });
                current.push((k, tracks.len() - 1));
            }
        }
        previous = current;
    }
    tracks
}

/// Join tracks of one mode that an order interrupted: two tracks with no order in common whose
/// medians repeat each other (3.3, the stability tolerances) become one, the stronger first.
fn join_interrupted(mut tracks: Vec<Track<'_>>) -> Vec<Track<'_>> {
    tracks.retain(|t| t.stable > 0);
    tracks.sort_by_key(|t| std::cmp::Reverse(t.stable));
    let mut joined: Vec<Track> = Vec::new();
    for t in tracks {
        let start = t.start();
        let home = joined.iter_mut().find(|j| {
            let js = j.start();
            let disjoint = !t.orders().any(|o| j.orders().any(|p| p == o));
            disjoint && repeats(start.s, t.last_shape(), js.s, j.last_shape())
        });
        match home {
            Some(j) => {
                j.stable += t.stable;
                j.members.extend(t.members);
                j.members.sort_by_key(|m| m.0);
            }
            None => joined.push(t),
        }
    }
    joined
}

/// The median of `values` (not empty).
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(f: f64, z: f64, shape: &[f64]) -> Candidate {
        Candidate {
            s: pole::from_frequency(f, z),
            shape: shape.iter().map(|&x| c64::new(x, 0.0)).collect(),
            amplitude: 1.0,
        }
    }

    /// A pole that repeats over the orders is a mode; one that wanders, or flips its shape, or
    /// has a negative ratio, is not.
    #[test]
    fn stable_poles_are_modes_and_wandering_ones_are_not() {
        let orders = vec![4, 6, 8, 10, 12];
        let candidates = (0..orders.len())
            .map(|i| {
                let k = i as f64;
                vec![
                    cand(3.0 * (1.0 + 1e-4 * k), 0.02, &[1.0, 0.5]),
                    cand(5.0 + 0.3 * k, 0.05, &[1.0, -1.0]),
                    cand(9.0, 0.03, if i % 2 == 0 { &[1.0, 0.0] } else { &[0.0, 1.0] }),
                    cand(12.0, -0.01, &[1.0, 1.0]),
                ]
            })
            .collect();
        let found = modes(&Diagram { orders, candidates }, 0.3, 0.3);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!((pole::frequency_hz(found[0].s) - 3.0006).abs() < 1e-3);
        assert_eq!(found[0].stable_orders, 4);
    }

    /// Two modes 1.4 % apart, of the same shape, whose candidates scatter into the gap between
    /// them (0.6 % wide at every order: a chain of neighbours less than 1 % apart runs from one
    /// to the other) stay two tracks.
    #[test]
    fn close_modes_stay_apart() {
        let orders: Vec<usize> = (4..=24).step_by(2).collect();
        let candidates = (0..orders.len())
            .map(|i| {
                let wobble = if i % 2 == 0 { 0.004 } else { -0.004 };
                vec![
                    cand(8.50 * (1.0 + wobble), 0.06, &[1.0, 0.3]),
                    cand(8.62 * (1.0 - wobble), 0.06, &[1.0, 0.3]),
                ]
            })
            .collect();
        let found = modes(&Diagram { orders, candidates }, 0.3, 0.3);
        assert_eq!(found.len(), 2, "{found:?}");
        assert!((pole::frequency_hz(found[0].s) - 8.50).abs() < 0.04);
        assert!((pole::frequency_hz(found[1].s) - 8.62).abs() < 0.04);
    }

    #[test]
    fn mac_of_parallel_and_orthogonal_shapes() {
        let a = [c64::new(1.0, 1.0), c64::new(2.0, -0.5)];
        let b: Vec<c64> = a.iter().map(|x| x * c64::new(0.0, -3.0)).collect();
        assert!((mac(&a, &b) - 1.0).abs() < 1e-14);
        assert!(
            mac(
                &[c64::new(1.0, 0.0), c64::new(0.0, 0.0)],
                &[c64::new(0.0, 0.0), c64::new(1.0, 0.0)]
            ) < 1e-14
        );
    }
}
