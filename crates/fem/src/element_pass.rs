//! The element loops of the time step (`docs/fem.md` section 6): every beam element's inertia and internal
//! forces into the imbalance, with its block `M + beta' K` of the Newton matrix at the first
//! iteration of a step, and the beams' kinetic and strain energy at the output times.
//!
//! Four consecutive elements are evaluated at once, one per lane of
//! [`flexstar_numerics::lanes::F64x4`], by the same [`ElementState`] methods as one element
//! (the last `n mod 4` elements take the one-element path). The lanes' arithmetic is that of one
//! element, operation for operation, so the results are bit for bit those of the element-by-element
//! loop (unit test below); the sums into the imbalance are taken in element order, as before. The
//! loops are compiled twice, for baseline x86-64 and for AVX2 (256-bit lanes), and the processor
//! picks at run time ([`flexstar_numerics::dispatch_avx2`]).

use flexstar_numerics::lanes::{F64x4, Real};

use crate::element::{chord_dissipation_power, Element, ElementState};

/// Section constants of one beam: axial stiffness EA [N], bending stiffness EI [N m^2], mass
/// per length rho [kg/m], and the Kelvin-Voigt retardation time beta [s] (Eq. D1; 0: undamped,
/// the damped code paths are then skipped; one value for the whole star).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Section {
    pub ea: f64,
    pub ei: f64,
    pub rho: f64,
    pub beta: f64,
}

/// The sections of the star's elements (`docs/fem.md` section 10, per-beam data): beam i's
/// [`Section`] for its `per_beam` consecutive elements `i per_beam .. (i + 1) per_beam` (the
/// element order of `crate::star`). A batch of four elements takes its lanes' section
/// constants from their beams: one beam's values in every lane (the common case, and the only
/// one when the three beams are equal), else lane by lane for a batch that straddles two beams.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sections {
    beams: [Section; 3],
    per_beam: usize,
    /// The three sections are equal: every batch takes beam 1's (the equal-beam path).
    uniform: bool,
}

/// The section constants of `T::LANES` elements, one per lane: EA [N], EI [N m^2], rho [kg/m],
/// beta [s].
#[derive(Clone, Copy)]
struct Lanes<T> {
    ea: T,
    ei: T,
    rho: T,
    beta: T,
}

impl Sections {
    /// Beam i's section for the `per_beam` elements of beam i (elements numbered beam by beam).
    pub fn per_beam(beams: [Section; 3], per_beam: usize) -> Self {
        Sections {
            beams,
            per_beam: per_beam.max(1),
            uniform: beams[1] == beams[0] && beams[2] == beams[0],
        }
    }

    /// One section for every element.
    #[cfg(test)]
    pub fn uniform(sec: Section) -> Self {
        Self::per_beam([sec; 3], usize::MAX)
    }

    /// The Kelvin-Voigt retardation time beta [s] (one for the star).
    pub fn beta(&self) -> f64 {
        self.beams[0].beta
    }

    /// The section of element `e`.
    #[inline(always)]
    pub fn of(&self, e: usize) -> &Section {
        if self.uniform {
            &self.beams[0]
        } else {
            &self.beams[(e / self.per_beam).min(2)]
        }
    }

    /// The lanes' section constants of the `T::LANES` elements from `start`: splat when they
    /// lie on one beam (bit for bit the constants of one element), else lane by lane.
    #[inline(always)]
    fn lanes<T: Real>(&self, start: usize) -> Lanes<T> {
        let first = self.of(start);
        if self.uniform || start / self.per_beam == (start + T::LANES - 1) / self.per_beam {
            return Lanes {
                ea: T::splat(first.ea),
                ei: T::splat(first.ei),
                rho: T::splat(first.rho),
                beta: T::splat(first.beta),
            };
        }
        Lanes {
            ea: T::from_lanes(|k| self.of(start + k).ea),
            ei: T::from_lanes(|k| self.of(start + k).ei),
            rho: T::from_lanes(|k| self.of(start + k).rho),
            beta: T::from_lanes(|k| self.of(start + k).beta),
        }
    }
}

/// Factors of the imbalance and of the Newton matrix: `cf` on the dynamic part of the imbalance,
/// `ck` on the stiffness in the matrix `cm M + ck K`, `cv` on the velocity derivative of the
/// forces (the damping matrix `beta K_mat`, Eq. D9), `cm` on the mass (`1 + gamma' alpha` with
/// the mass-proportional damping, Eq. D18; 1 without, and `rho * 1` is `rho` exactly). In a step
/// `cf = ck = beta'` [s^2] and `cv = gamma'` [s]; for the consistent initial accelerations
/// `cf = 1`, `ck = cv = 0`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Factors {
    pub cf: f64,
    pub ck: f64,
    pub cv: f64,
    pub cm: f64,
}

/// Global coordinates [m, rad], velocities and accelerations of the star's nodes (first
/// `3 n_nodes` entries used).
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeState<'a> {
    pub q: &'a [f64],
    pub v: &'a [f64],
    pub qdd: &'a [f64],
}

/// An element whose chord is not a positive finite length (a diverging iterate).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BadChord {
    pub element: usize,
    /// Chord length l_n [m].
    pub ln: f64,
}

/// Elements per batch.
const LANES: usize = 4;

/// Position of entry `j = 6 a + b` of element `e`'s 6 x 6 block `M + beta' K` in the value array
/// (the slot layout of `crate::star`): blocks stored by batches of four elements, entry by entry,
/// the four elements' values of one entry next to each other (so that a batch writes each entry
/// of its four lanes as one vector).
#[inline(always)]
pub(crate) fn block_index(e: usize, j: usize) -> usize {
    (e / LANES) * 36 * LANES + j * LANES + e % LANES
}

/// Values taken by the element blocks of `n` elements (whole batches; the lanes past the last
/// element are zero).
pub(crate) fn blocks_len(n: usize) -> usize {
    n.div_ceil(LANES) * 36 * LANES
}

/// Read access to one element's block, `block[6 a + b]` ([`block_index`]): its batch's values
/// and its lane.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Block<'a> {
    batch: &'a [f64; 36 * LANES],
    lane: usize,
}

static ZERO_BATCH: [f64; 36 * LANES] = [0.0; 36 * LANES];

impl<'a> Block<'a> {
    /// The block of element `e` in the value array `vals`.
    #[inline(always)]
    pub fn of(vals: &'a [f64], e: usize) -> Self {
        let at = block_index(e - e % LANES, 0);
        Block {
            batch: vals[at..at + 36 * LANES].try_into().expect("whole batches of blocks"),
            lane: e % LANES,
        }
    }

    /// A block of zeros.
    pub fn zero() -> Block<'static> {
        Block {
            batch: &ZERO_BATCH,
            lane: 0,
        }
    }
}

impl std::ops::Index<usize> for Block<'_> {
    type Output = f64;
    #[inline(always)]
    fn index(&self, j: usize) -> &f64 {
        &self.batch[LANES * j + self.lane]
    }
}

flexstar_numerics::dispatch_avx2! {
    /// Add `cf (M(q) qdd + f_conv(q, v) + f_int(q, v))` of every element to `res` (global DOFs,
    /// in element order) and, with `vals`, write each element's `M + ck K` (36 values, row-major,
    /// at [`block_index`]: the slot layout of `crate::star`). With damping (`sec.beta > 0`) the
    /// internal force is Eq. D7's and the block Eq. D9's `M + (ck + cv beta) K_mat + ck G`; the
    /// block's mass is `fac.cm M` (Eq. D18), the imbalance's inertia force uses `rho` itself.
    pub(crate) fn add_forces(
        elements: &[Element],
        nodes: NodeState,
        sec: &Sections,
        fac: Factors,
        res: &mut [f64],
        vals: Option<&mut [f64]>,
    ) -> Result<(), BadChord> {
        let terms = Terms { nodes, sec, fac };
        if sec.beta() > 0.0 {
            add_all::<true>(elements, &terms, res, vals)
        } else {
            add_all::<false>(elements, &terms, res, vals)
        }
    }
}

/// The batches of [`add_forces`], damped (Eqs. D7, D9) or not (two separate copies, so that the
/// undamped one is the code as it was before damping was added).
#[inline(always)]
fn add_all<const DAMPED: bool>(
    elements: &[Element],
    terms: &Terms,
    res: &mut [f64],
    vals: Option<&mut [f64]>,
) -> Result<(), BadChord> {
    let mut vals = vals;
    let full = elements.len() / LANES * LANES;
    for start in (0..full).step_by(LANES) {
        add_forces_of::<F64x4, DAMPED>(elements, start, terms, res, vals.as_deref_mut())?;
    }
    for start in full..elements.len() {
        add_forces_of::<f64, DAMPED>(elements, start, terms, res, vals.as_deref_mut())?;
    }
    Ok(())
}

flexstar_numerics::dispatch_avx2! {
    /// Dissipated power of all elements [W], Eq. D10: `sum beta p'^T K_l p'`
    /// ([`ElementState::dissipation_power`], sums in element order).
    pub(crate) fn dissipation_power(elements: &[Element], q: &[f64], v: &[f64], sec: &Sections) -> f64 {
        let full = elements.len() / LANES * LANES;
        let mut sum = 0.0;
        for start in (0..full).step_by(LANES) {
            sum += power_of::<F64x4>(elements, start, q, v, sec);
        }
        for start in full..elements.len() {
            sum += power_of::<f64>(elements, start, q, v, sec);
        }
        sum
    }
}

flexstar_numerics::dispatch_avx2! {
    /// `sum_e x_e^T M_e y_e` over the elements at the global coordinates `q` (`x`, `y` global
    /// vectors; for velocities [m/s, rad/s] and rates [1/s^2] a power [W], Eq. D16).
    pub(crate) fn mass_product(elements: &[Element], q: &[f64], x: &[f64], y: &[f64], sec: &Sections) -> f64 {
        let full = elements.len() / LANES * LANES;
        let mut sum = 0.0;
        for start in (0..full).step_by(LANES) {
            sum += mass_product_of::<F64x4>(elements, start, [q, x, y], sec);
        }
        for start in full..elements.len() {
            sum += mass_product_of::<f64>(elements, start, [q, x, y], sec);
        }
        sum
    }
}

flexstar_numerics::dispatch_avx2! {
    /// Kinetic and strain energy of all elements [J] (sums in element order):
    /// [`ElementState::kinetic_energy`], [`ElementState::strain_energy`].
    pub(crate) fn energies(elements: &[Element], q: &[f64], v: &[f64], sec: &Sections) -> (f64, f64) {
        let full = elements.len() / LANES * LANES;
        let mut sums = (0.0, 0.0);
        for start in (0..full).step_by(LANES) {
            energies_of::<F64x4>(elements, start, q, v, sec, &mut sums);
        }
        for start in full..elements.len() {
            energies_of::<f64>(elements, start, q, v, sec, &mut sums);
        }
        sums
    }
}

/// First node of the `T::LANES` elements from `start` if they form a chain `n0, n0 + 1, ...`
/// (consecutive elements of one beam: every batch but the one holding a beam's first element,
/// whose first node is G), whose nodes' DOFs are then one contiguous run of the global vectors.
#[inline(always)]
fn chain<T: Real>(elements: &[Element], start: usize) -> Option<usize> {
    let n0 = elements[start].nodes[0];
    (0..T::LANES)
        .all(|k| elements[start + k].nodes == [n0 + k, n0 + k + 1])
        .then_some(n0)
}

/// Element DOFs `[xa, ya, phia, xb, yb, phib]` of the `T::LANES` elements from `start`, one per
/// lane, from the global vector `x`: one contiguous run for a chain (`chain`, its first node),
/// else one bounds check per node.
#[inline(always)]
fn gather<T: Real>(elements: &[Element], start: usize, chain: Option<usize>, x: &[f64]) -> [T; 6] {
    let mut out = [T::splat(0.0); 6];
    if let Some(n0) = chain {
        let run = &x[3 * n0..3 * (n0 + T::LANES + 1)];
        for c in 0..3 {
            out[c] = T::from_lanes(|k| run[3 * k + c]);
            out[3 + c] = T::from_lanes(|k| run[3 * (k + 1) + c]);
        }
        return out;
    }
    let mut rows = [[0.0; 6]; LANES];
    for k in 0..T::LANES {
        let [a, b] = elements[start + k].nodes;
        let (xa, xb) = (node_dofs(x, a), node_dofs(x, b));
        rows[k] = [xa[0], xa[1], xa[2], xb[0], xb[1], xb[2]];
    }
    for c in 0..6 {
        out[c] = T::from_lanes(|k| rows[k][c]);
    }
    out
}

/// `[x, y, phi]` of node `j` in the global vector `x`.
#[inline(always)]
fn node_dofs(x: &[f64], j: usize) -> &[f64; 3] {
    x[3 * j..3 * j + 3].try_into().expect("three DOFs per node")
}

/// Add `f` (element DOFs, one element per lane) to the global vector `res`, lane after lane
/// (node a, then node b: the order of the element-by-element loop).
#[inline(always)]
fn scatter_add<T: Real>(elements: &[Element], start: usize, chain: Option<usize>, f: &[T; 6], res: &mut [f64]) {
    if let Some(n0) = chain {
        let run = &mut res[3 * n0..3 * (n0 + T::LANES + 1)];
        for k in 0..T::LANES {
            for a in 0..6 {
                run[3 * k + a] += f[a].lane(k);
            }
        }
        return;
    }
    for k in 0..T::LANES {
        let [a, b] = elements[start + k].nodes;
        for (node, off) in [(a, 0), (b, 3)] {
            let r: &mut [f64; 3] = (&mut res[3 * node..3 * node + 3])
                .try_into()
                .expect("three DOFs per node");
            for c in 0..3 {
                r[c] += f[off + c].lane(k);
            }
        }
    }
}

/// States of the `T::LANES` elements from `start` at the global coordinates `q`.
#[inline(always)]
fn states<T: Real>(elements: &[Element], start: usize, chain: Option<usize>, q: &[f64]) -> ElementState<T> {
    let el = |k: usize| &elements[start + k];
    ElementState::from_reference(
        T::from_lanes(|k| el(k).l0),
        T::from_lanes(|k| el(k).c0),
        T::from_lanes(|k| el(k).s0),
        &gather(elements, start, chain, q),
    )
}

/// What [`add_forces`] evaluates every batch at: the nodes' state, the section, and the scales
/// of the imbalance (`cf`) and of the stiffness in the matrix (`ck`).
#[derive(Clone, Copy)]
struct Terms<'a> {
    nodes: NodeState<'a>,
    sec: &'a Sections,
    fac: Factors,
}

/// One batch of [`add_forces`]. The `std::hint::black_box` calls keep each lane result in memory
/// as four consecutive doubles: that is where the compiler's straight-line vectoriser starts
/// from. Without them the lanes' results meet only scalar scatters and most of the arithmetic
/// stays scalar (callgrind, 300 elements, when they were introduced: 1800 instructions per
/// four-element batch without the matrix, 1190 with them; 2900 and 2370 with it). They change
/// no value.
#[inline(always)]
fn add_forces_of<T: Real, const DAMPED: bool>(
    elements: &[Element],
    start: usize,
    terms: &Terms,
    res: &mut [f64],
    vals: Option<&mut [f64]>,
) -> Result<(), BadChord> {
    let Terms { nodes, sec, fac } = *terms;
    let Factors { cf, ck, cv, cm } = fac;
    let sec: Lanes<T> = sec.lanes(start);
    let damped = [sec.ea, sec.ei, sec.beta];
    let chain = chain::<T>(elements, start);
    let st: ElementState<T> = states(elements, start, chain, nodes.q);
    for k in 0..T::LANES {
        let ln = st.ln.lane(k);
        if !(ln.is_finite() && ln > 0.0) {
            return Err(BadChord { element: start + k, ln });
        }
    }
    let (ve, ae) = (
        gather(elements, start, chain, nodes.v),
        gather(elements, start, chain, nodes.qdd),
    );
    let fm = std::hint::black_box(st.inertia_force(sec.rho, &ve, &ae));
    let fi = match vals {
        Some(vals) => {
            // Eq. D9 when damped: the factors are in the tangent already
            let (fi, kt) = if DAMPED {
                let (c_mat, c_geo) = (T::splat(ck) + sec.beta * cv, T::splat(ck));
                st.damped_internal(damped, &ve, c_mat, c_geo)
            } else {
                st.internal(sec.ea, sec.ei)
            };
            let m = std::hint::black_box(st.mass(sec.rho * cm));
            let mut mk = m;
            for a in 0..6 {
                for b in 0..6 {
                    mk[a][b] = if DAMPED {
                        m[a][b] + kt[a][b]
                    } else {
                        m[a][b] + kt[a][b] * ck
                    };
                }
            }
            let mk = std::hint::black_box(mk);
            // a batch's block: 36 runs of four consecutive values (one vector store each)
            let block = &mut vals[block_index(start, 0)..block_index(start, 35) + T::LANES];
            let first = block_index(start, 0);
            for a in 0..6 {
                for b in 0..6 {
                    for k in 0..T::LANES {
                        block[block_index(start + k, 6 * a + b) - first] = mk[a][b].lane(k);
                    }
                }
            }
            fi
        }
        None if DAMPED => st.damped_internal_force(damped, &ve),
        None => st.internal_force(sec.ea, sec.ei),
    };
    let mut f = fm;
    for a in 0..6 {
        f[a] = (fm[a] + fi[a]) * cf;
    }
    let f = std::hint::black_box(f);
    scatter_add(elements, start, chain, &f, res);
    Ok(())
}

/// Dissipated power of the `T::LANES` elements from `start` [W] (lanes summed in order).
#[inline(always)]
fn power_of<T: Real>(elements: &[Element], start: usize, q: &[f64], v: &[f64], sec: &Sections) -> f64 {
    let sec: Lanes<T> = sec.lanes(start);
    let chain = chain::<T>(elements, start);
    let (pos, vel) = (gather(elements, start, chain, q), gather(elements, start, chain, v));
    let l0 = T::from_lanes(|k| elements[start + k].l0);
    let p = std::hint::black_box(chord_dissipation_power(l0, &pos, &vel, [sec.ea, sec.ei, sec.beta]));
    let mut sum = 0.0;
    for k in 0..T::LANES {
        sum += p.lane(k);
    }
    sum
}

/// [`mass_product`] for the `T::LANES` elements from `start` at `[q, x, y]` (lanes summed in
/// order).
#[inline(always)]
fn mass_product_of<T: Real>(elements: &[Element], start: usize, [q, x, y]: [&[f64]; 3], sec: &Sections) -> f64 {
    let rho = sec.lanes::<T>(start).rho;
    let chain = chain::<T>(elements, start);
    let st: ElementState<T> = states(elements, start, chain, q);
    let m = st.mass(rho);
    let (xe, ye): ([T; 6], [T; 6]) = (gather(elements, start, chain, x), gather(elements, start, chain, y));
    let mut p = T::splat(0.0);
    for a in 0..6 {
        let mut my = T::splat(0.0);
        for b in 0..6 {
            my += m[a][b] * ye[b];
        }
        p += xe[a] * my;
    }
    (0..T::LANES).map(|k| p.lane(k)).sum()
}

#[inline(always)]
fn energies_of<T: Real>(
    elements: &[Element],
    start: usize,
    q: &[f64],
    v: &[f64],
    sec: &Sections,
    sums: &mut (f64, f64),
) {
    let sec: Lanes<T> = sec.lanes(start);
    let chain = chain::<T>(elements, start);
    let st: ElementState<T> = states(elements, start, chain, q);
    let ke = st.kinetic_energy(sec.rho, &gather(elements, start, chain, v));
    let [ke, se] = std::hint::black_box([ke, st.strain_energy(sec.ea, sec.ei)]);
    for k in 0..T::LANES {
        sums.0 += ke.lane(k);
        sums.1 += se.lane(k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bent, stretched, rotating chain of `n` elements (node 0 shared, as G is).
    fn chain(n: usize) -> (Vec<Element>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let l0 = 0.01;
        let b0: f64 = 0.4;
        let elements: Vec<Element> = (0..n)
            .map(|k| Element {
                nodes: [k, k + 1],
                l0,
                c0: b0.cos(),
                s0: b0.sin(),
            })
            .collect();
        let mut q = vec![0.0; 3 * (n + 1)];
        let (mut v, mut a) = (q.clone(), q.clone());
        for j in 0..=n {
            let x = j as f64 * l0 * (1.0 + 1e-4 * (j as f64).sin());
            let w = 1e-3 * (0.3 * j as f64).sin();
            q[3 * j] = x * b0.cos() - w * b0.sin();
            q[3 * j + 1] = x * b0.sin() + w * b0.cos();
            // node rotations beyond +-pi too: the wrap's library path
            q[3 * j + 2] = 0.1 * (0.2 * j as f64).cos() + if j % 5 == 3 { 2.0 * std::f64::consts::PI } else { 0.0 };
            for c in 0..3 {
                v[3 * j + c] = (1.7 * j as f64 + c as f64).sin();
                a[3 * j + c] = 30.0 * (0.9 * j as f64 - c as f64).cos();
            }
        }
        (elements, q, v, a)
    }

    /// The element-by-element loop the batches replace (the loop of `Star::assemble` before them).
    fn one_by_one(
        elements: &[Element],
        nodes: NodeState,
        sec: Section,
        cf: f64,
        ck: f64,
        res: &mut [f64],
        vals: &mut [f64],
    ) {
        for (e, el) in elements.iter().enumerate() {
            let pick = |x: &[f64]| -> [f64; 6] {
                let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
                [x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2]]
            };
            let st = ElementState::new(el, &pick(nodes.q));
            let fm = st.inertia_force(sec.rho, &pick(nodes.v), &pick(nodes.qdd));
            let (fi, k) = st.internal(sec.ea, sec.ei);
            let m = st.mass(sec.rho);
            let d = [0, 1, 2, 3, 4, 5].map(|a| 3 * el.nodes[a / 3] + a % 3);
            for a in 0..6 {
                for b in 0..6 {
                    vals[block_index(e, 6 * a + b)] = m[a][b] + ck * k[a][b];
                }
                res[d[a]] += cf * (fm[a] + fi[a]);
            }
        }
    }

    #[test]
    fn batches_give_the_element_by_element_results_bit_for_bit() {
        let sec = Section {
            ea: 6e6,
            ei: 0.5,
            rho: 0.27,
            beta: 0.0,
        };
        let (cf, ck) = (6e-8, 6e-8);
        let fac = Factors {
            cf,
            ck,
            cv: 2.6e-4,
            cm: 1.0,
        };
        // 11 elements: two full batches and a remainder of three
        let (elements, q, v, a) = chain(11);
        let nodes = NodeState { q: &q, v: &v, qdd: &a };
        let (mut r1, mut m1) = (vec![0.0; q.len()], vec![0.0; blocks_len(elements.len())]);
        let (mut r2, mut m2) = (r1.clone(), m1.clone());
        one_by_one(&elements, nodes, sec, cf, ck, &mut r1, &mut m1);
        add_forces(&elements, nodes, &Sections::uniform(sec), fac, &mut r2, Some(&mut m2)).unwrap();
        assert_eq!(
            r1.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            r2.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(
            m1.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            m2.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        // the imbalance-only pass adds the same forces
        let mut r3 = vec![0.0; q.len()];
        add_forces(&elements, nodes, &Sections::uniform(sec), fac, &mut r3, None).unwrap();
        assert_eq!(r1, r3);
        // energies against the element-by-element sums
        let (mut t, mut u) = (0.0, 0.0);
        for el in &elements {
            let pick = |x: &[f64]| -> [f64; 6] {
                let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
                [x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2]]
            };
            let st = ElementState::new(el, &pick(&q));
            t += st.kinetic_energy(sec.rho, &pick(&v));
            u += st.strain_energy(sec.ea, sec.ei);
        }
        assert_eq!(energies(&elements, &q, &v, &Sections::uniform(sec)), (t, u));
        assert!(t > 0.0 && u > 0.0);
    }

    /// Per-beam sections (`docs/fem.md` section 10): three beams of three elements each (the
    /// chain's last two on beam 3), so that both batches of four straddle two beams and take their
    /// lanes' constants one by one; the batches give each element's own results bit for bit,
    /// damped and undamped, and the energies and powers sum each element's with its own section.
    #[test]
    fn batches_across_beams_take_each_element_its_own_section() {
        let beams = [
            Section {
                ea: 6e6,
                ei: 0.5,
                rho: 0.234,
                beta: 8e-4,
            },
            Section {
                ea: 7e6,
                ei: 0.63,
                rho: 0.21,
                beta: 8e-4,
            },
            Section {
                ea: 5e6,
                ei: 0.41,
                rho: 0.26,
                beta: 8e-4,
            },
        ];
        let (elements, q, v, a) = chain(11);
        let nodes = NodeState { q: &q, v: &v, qdd: &a };
        let fac = Factors {
            cf: 6e-8,
            ck: 6e-8,
            cv: 2.6e-4,
            cm: 1.0,
        };
        for damped in [false, true] {
            let beta = if damped { 8e-4 } else { 0.0 };
            let beams = beams.map(|s| Section { beta, ..s });
            let sections = Sections::per_beam(beams, 3);
            let own = |e: usize| beams[(e / 3).min(2)];
            let (mut r1, mut m1) = (vec![0.0; q.len()], vec![0.0; blocks_len(elements.len())]);
            let (mut t, mut u, mut p) = (0.0, 0.0, 0.0);
            for (e, el) in elements.iter().enumerate() {
                let sec = own(e);
                let pick = |x: &[f64]| -> [f64; 6] {
                    let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
                    [x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2]]
                };
                let st = ElementState::new(el, &pick(&q));
                let fm = st.inertia_force(sec.rho, &pick(&v), &pick(&a));
                let (fi, k) = if damped {
                    let c_mat = fac.ck + fac.cv * sec.beta;
                    st.damped_internal([sec.ea, sec.ei, sec.beta], &pick(&v), c_mat, fac.ck)
                } else {
                    let (f, k) = st.internal(sec.ea, sec.ei);
                    (f, k.map(|row| row.map(|x| x * fac.ck)))
                };
                let m = st.mass(sec.rho);
                let d = [0, 1, 2, 3, 4, 5].map(|a| 3 * el.nodes[a / 3] + a % 3);
                for a in 0..6 {
                    for b in 0..6 {
                        m1[block_index(e, 6 * a + b)] = m[a][b] + k[a][b];
                    }
                    r1[d[a]] += fac.cf * (fm[a] + fi[a]);
                }
                t += st.kinetic_energy(sec.rho, &pick(&v));
                u += st.strain_energy(sec.ea, sec.ei);
                p += st.dissipation_power(sec.ea, sec.ei, sec.beta, &pick(&v));
            }
            let (mut r2, mut m2) = (vec![0.0; q.len()], vec![0.0; blocks_len(elements.len())]);
            add_forces(&elements, nodes, &sections, fac, &mut r2, Some(&mut m2)).unwrap();
            assert_eq!(r1, r2, "imbalance, damped: {damped}");
            assert_eq!(m1, m2, "blocks, damped: {damped}");
            assert_eq!(energies(&elements, &q, &v, &sections), (t, u));
            if damped {
                let pb = dissipation_power(&elements, &q, &v, &sections);
                assert!(p > 0.0 && (p - pb).abs() <= 1e-12 * p, "{p} vs {pb}");
            }
            // and the sections do matter: one section for all gives another imbalance
            let mut r3 = vec![0.0; q.len()];
            add_forces(&elements, nodes, &Sections::uniform(beams[0]), fac, &mut r3, None).unwrap();
            assert!(r1.iter().zip(&r3).any(|(x, y)| x != y));
        }
    }

    #[test]
    fn a_collapsed_chord_is_reported_with_its_element() {
        let sec = Section {
            ea: 6e6,
            ei: 0.5,
            rho: 0.27,
            beta: 0.0,
        };
        let (elements, mut q, v, a) = chain(9);
        // element 6 (in the second batch) collapses: node 7 onto node 6
        q[21] = q[18];
        q[22] = q[19];
        let mut res = vec![0.0; q.len()];
        let nodes = NodeState { q: &q, v: &v, qdd: &a };
        let err = add_forces(
            &elements,
            nodes,
            &Sections::uniform(sec),
            Factors {
                cf: 1.0,
                ck: 1.0,
                cv: 0.0,
                cm: 1.0,
            },
            &mut res,
            None,
        )
        .unwrap_err();
        assert_eq!(err, BadChord { element: 6, ln: 0.0 });
        // and in the remainder (element 8, the one-element path)
        let (elements, mut q, v, a) = chain(9);
        q[27] = f64::NAN;
        let nodes = NodeState { q: &q, v: &v, qdd: &a };
        let err = add_forces(
            &elements,
            nodes,
            &Sections::uniform(sec),
            Factors {
                cf: 1.0,
                ck: 1.0,
                cv: 0.0,
                cm: 1.0,
            },
            &mut res,
            None,
        )
        .unwrap_err();
        assert_eq!(err.element, 8);
        assert!(err.ln.is_nan());
    }

    #[test]
    fn damped_batches_give_the_element_by_element_results_bit_for_bit() {
        // Eqs. D7, D9 through the batches against each element's own damped force and tangent
        let sec = Section {
            ea: 6e6,
            ei: 0.5,
            rho: 0.27,
            beta: 8e-4,
        };
        let fac = Factors {
            cf: 6e-8,
            ck: 6e-8,
            cv: 2.6e-4,
            cm: 1.0,
        };
        let (elements, q, v, a) = chain(11);
        let nodes = NodeState { q: &q, v: &v, qdd: &a };
        let (mut r1, mut m1) = (vec![0.0; q.len()], vec![0.0; blocks_len(elements.len())]);
        for (e, el) in elements.iter().enumerate() {
            let pick = |x: &[f64]| -> [f64; 6] {
                let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
                [x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2]]
            };
            let st = ElementState::new(el, &pick(&q));
            let fm = st.inertia_force(sec.rho, &pick(&v), &pick(&a));
            let (c_mat, c_geo) = (fac.ck + fac.cv * sec.beta, fac.ck);
            let (fi, k) = st.damped_internal([sec.ea, sec.ei, sec.beta], &pick(&v), c_mat, c_geo);
            let m = st.mass(sec.rho);
            let d = [0, 1, 2, 3, 4, 5].map(|a| 3 * el.nodes[a / 3] + a % 3);
            for a in 0..6 {
                for b in 0..6 {
                    m1[block_index(e, 6 * a + b)] = m[a][b] + k[a][b];
                }
                r1[d[a]] += fac.cf * (fm[a] + fi[a]);
            }
        }
        let (mut r2, mut m2) = (vec![0.0; q.len()], vec![0.0; blocks_len(elements.len())]);
        add_forces(&elements, nodes, &Sections::uniform(sec), fac, &mut r2, Some(&mut m2)).unwrap();
        assert_eq!(r1, r2);
        assert_eq!(m1, m2);
        let mut r3 = vec![0.0; q.len()];
        add_forces(&elements, nodes, &Sections::uniform(sec), fac, &mut r3, None).unwrap();
        assert_eq!(r1, r3);
        // damping changes the imbalance (the chain deforms at a rate) and the power sums
        let mut r4 = vec![0.0; q.len()];
        add_forces(
            &elements,
            nodes,
            &Sections::uniform(Section { beta: 0.0, ..sec }),
            fac,
            &mut r4,
            None,
        )
        .unwrap();
        assert!(r1.iter().zip(&r4).any(|(x, y)| x != y));
        let p: f64 = elements
            .iter()
            .map(|el| {
                let pick = |x: &[f64]| -> [f64; 6] {
                    let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
                    [x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2]]
                };
                ElementState::new(el, &pick(&q)).dissipation_power(sec.ea, sec.ei, sec.beta, &pick(&v))
            })
            .sum();
        let pb = dissipation_power(&elements, &q, &v, &Sections::uniform(sec));
        assert!(p > 0.0 && (p - pb).abs() <= 1e-12 * p, "{p} vs {pb}");
    }
}
