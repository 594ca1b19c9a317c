//! The sleeves must stay on their beams (`docs/fem.md` 3, "Checks that stop the run"): each sleeve's
//! three contact points (its centre and its two edges, at material coordinates along its beam
//! from the junction G) inside the open interval `(0, L_i)` of the beam's length. The rigid
//! kinematics checks the rigid pose before a run (`flexstar_kinematics::feasibility`); the
//! elastic motion (the beam's axial displacement, its foreshortening) can still carry a contact
//! point off the beam during a run, which both solvers report with this error.

/// A sleeve contact point outside its beam, at time `t` [s]: sleeve `sleeve` (1-based), the
/// contact point `point` ("centre", "left edge" towards G, "right edge" towards the tip) at
/// material coordinate `xi` [m], the beam's length `l` [m].
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "sleeve {sleeve} slid off beam {sleeve} at t = {t:.6} s: the {point} contact point is at material coordinate {xi:.5} m, outside (0, L = {l} m)"
)]
pub struct OffBeam {
    pub t: f64,
    pub sleeve: usize,
    pub point: &'static str,
    pub xi: f64,
    pub l: f64,
}

/// The names of the contact points, in the order [`on_beam`] takes their coordinates.
pub const CONTACT_POINTS: [&str; 3] = ["centre", "left edge", "right edge"];

/// Check sleeve `i`'s (0-based) contact points at material coordinates `xi` [m] (centre, left
/// edge, right edge: [`CONTACT_POINTS`]) against its beam's length `l` [m] at time `t` [s]: the
/// first point outside `(0, l)` (or not finite) is the error.
pub fn on_beam(t: f64, i: usize, xi: [f64; 3], l: f64) -> Result<(), OffBeam> {
    match xi.iter().position(|&x| !(x > 0.0 && x < l)) {
        None => Ok(()),
        Some(p) => Err(OffBeam {
            t,
            sleeve: i + 1,
            point: CONTACT_POINTS[p],
            xi: xi[p],
            l,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_outside_the_beam_is_named() {
        assert_eq!(on_beam(0.1, 0, [0.25, 0.24, 0.26], 0.5), Ok(()));
        let e = on_beam(0.2, 2, [0.49, 0.48, 0.5], 0.5).unwrap_err();
        assert_eq!((e.sleeve, e.point, e.xi), (3, "right edge", 0.5));
        let e = on_beam(0.3, 1, [0.01, -0.005, 0.025], 0.5).unwrap_err();
        assert_eq!((e.sleeve, e.point), (2, "left edge"));
        assert!(e
            .to_string()
            .starts_with("sleeve 2 slid off beam 2 at t = 0.300000 s: the left edge"));
        assert!(on_beam(0.0, 0, [f64::NAN, 0.1, 0.2], 0.5).is_err());
    }
}
