//! Measuring speed and error: per-pass GPU timing against floors ([`bench`]), quality knobs
//! swept against references ([`sweep`]), and the hard numerical cases ([`hard_cases`]). Each
//! keeps its results in the output folder and contributes a section to the review page through
//! [`crate::report::Section`].

pub mod bench;
pub mod hard_cases;
pub mod speed;
pub mod sweep;

use std::path::Path;

use crate::report::Section;

/// The review page's section of the latest `harness bench` results.
pub struct BenchSection;

impl Section for BenchSection {
    fn html(&self, dir: &Path) -> String {
        bench::report_sections(dir)
    }
}

/// The review page's section of the sweeps kept by `harness sweep`.
pub struct SweepSection;

impl Section for SweepSection {
    fn html(&self, dir: &Path) -> String {
        sweep::report_sections(dir)
    }
}

/// The review page's section of the latest `harness hard` results.
pub struct HardCasesSection;

impl Section for HardCasesSection {
    fn html(&self, dir: &Path) -> String {
        hard_cases::report_section(dir)
    }
}

/// The review page's plots of the speed history kept by `harness check`.
pub struct SpeedHistorySection;

impl Section for SpeedHistorySection {
    fn html(&self, dir: &Path) -> String {
        crate::golden::speed::history::report_section(dir)
    }
}

/// Every section the measurements add to the review page, in page order.
pub fn report_sections() -> [&'static dyn Section; 4] {
    [
        &SpeedHistorySection,
        &BenchSection,
        &SweepSection,
        &HardCasesSection,
    ]
}
