//! The slot layout (sparsity pattern) of the star's iteration matrix: element blocks, sleeve
//! diagonals, the constraint rows in their windows of elements, the slider rows; rebuilt when a
//! contact point leaves its window.

use super::*;

impl Star {
    /// Rebuild the pattern (slot layout of the constraint rows) if a contact point left its
    /// window; the sparse LU's symbolic factorisation is then redone on demand. Returns whether
    /// the pattern was rebuilt.
    pub(super) fn ensure_pattern(&mut self, q: &[f64]) -> bool {
        let mut rebuild = self.bordered.is_none();
        for i in 0..3 {
            for p in 0..3 {
                let (e, _) = self.locate(i, q[self.xi(i, p)]);
                let lo = self.win[i][p];
                if lo == usize::MAX || e < lo || e >= lo + self.ww {
                    rebuild = true;
                    self.win[i][p] = e.saturating_sub(self.ww / 2).min(self.ne - self.ww);
                }
            }
        }
        if !rebuild {
            return false;
        }
        if self.bordered.is_none() {
            self.build_pattern();
        } else {
            // only the constraint rows' columns move with the windows: their slots are
            // rewritten in place (same count), everything else stays
            let con = self.constraint_slots();
            self.slots[self.off_con..self.off_sl].copy_from_slice(&con);
        }
        self.lu = None;
        self.symbolic_count += 1;
        true
    }

    /// The whole slot layout and the structured solver, at the first assembly: element blocks,
    /// sleeve diagonals, constraint rows ([`Star::constraint_slots`]), slider rows.
    pub(super) fn build_pattern(&mut self) {
        // element blocks at element_pass::block_index; the lanes past the last element repeat
        // the last element's slots (their values are zero)
        let n_el = self.elements.len();
        let mut slots = vec![(0, 0); element_pass::blocks_len(n_el)];
        for e in 0..element_pass::blocks_len(n_el) / 36 {
            let d = dofs(&self.elements[e.min(n_el - 1)]);
            for a in 0..6 {
                for b in 0..6 {
                    slots[element_pass::block_index(e, 6 * a + b)] = (d[a], d[b]);
                }
            }
        }
        self.off_psi = slots.len();
        for i in 0..3 {
            slots.push((self.psi(i), self.psi(i)));
            for p in 0..3 {
                slots.push((self.xi(i, p), self.xi(i, p)));
            }
        }
        self.off_con = slots.len();
        slots.extend(self.constraint_slots());
        self.off_sl = slots.len();
        if self.direct {
            for i in 0..3 {
                let s = self.slider(i);
                slots.push((s, s));
                for r in 0..6 {
                    let row = self.n_dof + ROWS * i + r;
                    slots.push((row, s));
                    slots.push((s, row));
                }
            }
        }
        self.off_nu = slots.len();
        for i in 0..3 {
            let tangent = self.n_dof + ROWS * i + ROWS - 1;
            for r in NU_COLUMNS {
                slots.push((tangent, self.n_dof + ROWS * i + r));
            }
        }
        self.off_fr = slots.len();
        let sleeves_rub = self.friction.as_ref().is_some_and(|f| f.law.sleeves_rub());
        if sleeves_rub {
            for i in 0..3 {
                let xc = self.xi(i, 0);
                for r in 0..FRICTION_SLOTS {
                    slots.push((xc, self.n_dof + ROWS * i + r));
                }
            }
        }
        self.bordered = Some(Bordered::new(Layout {
            ne: self.ne,
            n_nodes: self.n_nodes,
            n_dof: self.n_dof,
            off_psi: self.off_psi,
            off_con: self.off_con,
            ncol: self.ncol_c,
            ww: self.ww,
            off_sl: self.direct.then_some(self.off_sl),
            off_nu: self.off_nu,
            off_fr: sleeves_rub.then_some(self.off_fr),
        }));
        self.vals = vec![0.0; slots.len()];
        self.slots = slots;
    }

    /// Slots of the constraint rows in the current windows: per row its window columns
    /// ([`Star::window_cols`]), then the transposed block.
    pub(super) fn constraint_slots(&self) -> Vec<(usize, usize)> {
        let mut slots = Vec::with_capacity(3 * ROWS * 2 * self.ncol_c);
        for i in 0..3 {
            for r in 0..ROWS {
                let row = self.n_dof + ROWS * i + r;
                let cols = self.window_cols(i, ROW_POINT[r]);
                slots.extend(cols.iter().map(|&c| (row, c)));
                slots.extend(cols.iter().map(|&c| (c, row)));
            }
        }
        slots
    }

    /// Columns of a constraint row of contact point p of sleeve i: the window's node DOFs, then
    /// the contact coordinate, then the sleeve rotation.
    pub(super) fn window_cols(&self, i: usize, p: usize) -> Vec<usize> {
        let lo = self.win[i][p];
        let mut c = Vec::with_capacity(self.ncol_c);
        for k in lo..=lo + self.ww {
            let j = self.node(i, k);
            c.extend_from_slice(&[3 * j, 3 * j + 1, 3 * j + 2]);
        }
        c.push(self.xi(i, p));
        c.push(self.psi(i));
        c
    }
}
