//! Compiles the peers' generated code (`python3 peers/generate.py` writes it
//! to peers/generated/): SymForce's C++ (header-only, over Eigen) through
//! the wrappers the script writes, and CasADi's C.

use std::path::Path;

fn main() {
    let dir = Path::new("generated");
    println!("cargo:rerun-if-changed=generated");
    println!("cargo:rerun-if-env-changed=EIGEN3_INCLUDE_DIR");
    let names = match std::fs::read_to_string(dir.join("casadi_names.txt")) {
        Ok(s) => s,
        Err(e) => panic!(
            "peers/generated/ is missing or incomplete ({e}): run `python3 peers/generate.py` \
             from the repository root first (peers/README.md)"
        ),
    };
    let eigen =
        std::env::var("EIGEN3_INCLUDE_DIR").unwrap_or_else(|_| "/usr/include/eigen3".into());
    assert!(
        Path::new(&eigen).join("Eigen/Core").exists(),
        "Eigen's headers are not in {eigen} (install libeigen3-dev or set EIGEN3_INCLUDE_DIR)"
    );
    cc::Build::new()
        .cpp(true)
        .std("c++17")
        .include(&eigen)
        .include(dir)
        .file(dir.join("symforce.cc"))
        .warnings(false)
        .compile("symforce_peer");
    let mut casadi = cc::Build::new();
    for name in names.lines().filter(|l| !l.is_empty()) {
        casadi.file(dir.join(format!("ca_{name}.c")));
    }
    casadi.warnings(false).compile("casadi_peer");
}
