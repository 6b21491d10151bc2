//! The shipped URDFs with some attribute numbers (masses, inertias, origins, axes, limits,
//! sizes) replaced by edge values or arbitrary floats, then run like `urdf_parse`.
//! `SIM_FUZZ_DUMP=1` prints each mutated document to stderr (to read a crash input).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let xml = sim_fuzz::mutate_seed(data);
    if std::env::var_os("SIM_FUZZ_DUMP").is_some() {
        eprintln!("{xml}");
    }
    sim_fuzz::exercise(&xml);
});
