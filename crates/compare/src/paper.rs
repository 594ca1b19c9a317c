//! The paper's Table I, as printed, for display beside the regenerated one.
//!
//! Source: paper, Table I and sections 8-9, with the two printing defects of MODEL-NOTES
//! section 5 corrected: the case-4 row repeats case 3's numbers (so case 4 has no usable EVPs,
//! shown as `None`) and slide-free in case 1 is incorrect according to the text.

use flexstar_model::ModeFamily;

use crate::behaviour::Behaviour;

/// One case of the paper's Table I.
#[derive(Debug, Clone, Copy)]
pub struct PaperCase {
    pub case: &'static str,
    pub motion: &'static str,
    pub behaviour: Behaviour,
    /// Mean EVP [%] for pinned-free, slide-free, free-free.
    pub evp: [Option<f64>; 3],
    /// Correct verdict for pinned-free, slide-free, free-free.
    pub correct: [bool; 3],
    pub most_accurate: ModeFamily,
}

/// Table I of the paper (N = 25 modes, 300 commercial-FEM elements).
pub const PAPER_TABLE: [PaperCase; 4] = [
    PaperCase {
        case: "case1",
        motion: "in-place rotation",
        behaviour: Behaviour::Pinned,
        evp: [Some(4.11), Some(33.46), Some(4.61)],
        correct: [true, false, true],
        most_accurate: ModeFamily::PinnedFree,
    },
    PaperCase {
        case: "case2",
        motion: "translation along X",
        behaviour: Behaviour::Slide,
        evp: [Some(125.57), Some(22.50), Some(32.21)],
        correct: [false, true, true],
        most_accurate: ModeFamily::SlideFree,
    },
    PaperCase {
        case: "case3",
        motion: "general plane motion",
        behaviour: Behaviour::General,
        evp: [Some(74.61), Some(55.76), Some(24.22)],
        correct: [false, false, true],
        most_accurate: ModeFamily::FreeFree,
    },
    PaperCase {
        case: "case4",
        motion: "translation along beam 3",
        behaviour: Behaviour::Slide,
        evp: [None, None, None],
        correct: [false, true, true],
        most_accurate: ModeFamily::SlideFree,
    },
];

/// The paper's entry for a case name, if it is one of the four.
pub fn paper_case(name: &str) -> Option<&'static PaperCase> {
    PAPER_TABLE.iter().find(|c| c.case == name)
}
