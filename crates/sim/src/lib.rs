//! `sim`: the plants latentrl learns to control.
#![warn(missing_docs)]
