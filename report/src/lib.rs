//! # splitsum-report
//!
//! How accurate and how fast splitsum is: [`report`] measures every product, and the
//! shaded colour a renderer shows at every roughness and view ([`accuracy`]), against
//! independent f64 references (`splitsum-reference`), per backend, with their run times
//! ([`measurement`]: error against run time), and plots them ([`plot`]).
//!
//! Depends on `splitsum` and the references, and nothing above them.

#![warn(missing_docs)]

pub mod accuracy;
pub mod measurement;
pub mod plot;
pub mod report;
