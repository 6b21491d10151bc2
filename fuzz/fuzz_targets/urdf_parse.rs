//! Arbitrary bytes as a URDF: parse, build fixed- and floating-root worlds, step, read.
//! Seeds: `python/latentrl/data/` (the shipped URDFs); dictionary: `fuzz/urdf.dict`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(xml) = std::str::from_utf8(data) {
        sim_fuzz::exercise(xml);
    }
});
