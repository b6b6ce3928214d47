//! # splitsum-report
//!
//! How accurate and how fast splitsum is: [`report`] measures every product, and the
//! shaded colour a renderer shows at every roughness and view ([`accuracy`]), against
//! independent f64 references (`splitsum-reference`), per backend, with their run times
//! ([`measurement`]: error against run time), plots them ([`plot`]) and shows the error
//! on surfaces ([`surface`]), in one page (`report.html`).
//!
//! Depends on `splitsum` and the references, and nothing above them.

#![cfg_attr(not(test), warn(unused_crate_dependencies))]
#![warn(missing_docs)]

pub mod accuracy;
pub mod figures;
pub mod horizon;
pub mod measurement;
pub mod pages;
pub mod plot;
pub mod report;
pub mod sets;
pub mod skies;
pub mod surface;
pub mod sweep;
mod write;
