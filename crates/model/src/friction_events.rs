//! Locating a stick or slip event within a time step, shared by both solvers
//! (`docs/friction.md` 9.5, Eq. F24): each contact change of a step is placed where its
//! quantity (a slipping contact's speed, a stuck one's excess force over its limit) crosses zero,
//! linearly between the step's start and end; the first one sets the part step, and the changes
//! that fall with it are taken together.

/// An event closer than this fraction of the step, or than [`MIN_PART`], to the step's start or
/// end is taken there: a part step of a tiny fraction costs a solve for nothing, and in the AMM
/// it would make `beta'` vanish against the rows' compliances (`docs/amm.md` Eqs. A3, F16, R4
/// divide by it: a part step of 2.6e-8 s left the Schur complement rank deficient to the LU's
/// test).
pub const THETA_MIN: f64 = 0.01;

/// The shortest part step [s] (see [`THETA_MIN`]): below steps of 1e-4 s the events are located
/// to this.
pub const MIN_PART: f64 = 1e-6;

/// Eq. F24: where a quantity going from `a` (the step's start) to `b` (its end), of opposite
/// sign or zero at the end, crosses zero, as a fraction of the step in [0, 1]; 0 when it already
/// had the end's sign at the start.
pub fn crossing(a: f64, b: f64) -> f64 {
    if a == 0.0 || a.signum() == b.signum() && b != 0.0 {
        return 0.0;
    }
    (a / (a - b)).clamp(0.0, 1.0)
}

/// Eq. F24 over a step of `h` [s]: the fraction `theta` at which the first of the changes
/// falls (`times[k]`, from [`crossing`], the fraction of `change[k]`), snapped to 0 or 1 within
/// [`THETA_MIN`] or [`MIN_PART`] of the step's ends, and the changes that fall there (within
/// 1e-9 of the step, or within the snapping margin of its start).
pub fn first_event<T: Copy>(change: &[T], times: &[f64], h: f64) -> (f64, Vec<T>) {
    let least = THETA_MIN.max(MIN_PART / h);
    let theta = match times.iter().copied().fold(1.0, f64::min) {
        t if t < least => 0.0,
        t if t > 1.0 - least => 1.0,
        t => t,
    };
    let due = change
        .iter()
        .zip(times)
        .filter(|(_, &t)| t <= theta.max(least) + 1e-9)
        .map(|(c, _)| *c)
        .collect();
    (theta, due)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crossing_is_interpolated_linearly_within_the_step() {
        assert_eq!(crossing(1.0, -3.0), 0.25);
        assert_eq!(crossing(-2.0, 2.0), 0.5);
        assert_eq!(crossing(1.0, 0.0), 1.0);
        // the end's sign at the start: the event is at the start
        assert_eq!(crossing(-1.0, -2.0), 0.0);
        assert_eq!(crossing(0.0, 1.0), 0.0);
    }

    /// The first event sets theta; a change within 1e-9 of it comes with it; events within the
    /// margin of the ends snap to them (1 % of a 1e-3 s step; 1e-6 s of a 1e-5 s step).
    #[test]
    fn the_first_event_takes_the_changes_that_fall_with_it() {
        assert_eq!(
            first_event(&['a', 'b', 'c'], &[0.5, 0.3, 0.3 + 1e-10], 1e-3),
            (0.3, vec!['b', 'c'])
        );
        assert_eq!(first_event(&['a', 'b'], &[0.005, 0.6], 1e-3), (0.0, vec!['a']));
        assert_eq!(first_event(&['a'], &[0.995], 1e-3), (1.0, vec!['a']));
        assert_eq!(first_event(&['a', 'b'], &[0.05, 0.09], 1e-5), (0.0, vec!['a', 'b']));
    }
}
