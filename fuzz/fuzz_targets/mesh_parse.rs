//! Arbitrary bytes as a collision mesh (issue #17): STL, OBJ or COLLADA by the first byte, then
//! the hull and the collider shape. Must return a hull or an error, never panic.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else { return };
    let name = ["mesh.stl", "mesh.obj", "mesh.dae"][usize::from(kind % 3)];
    let _ = sim::urdf::mesh::hull_of_bytes(bytes, Path::new(name), [1.0, 1.0, 1.0]);
});
