//! Generator time per model: derivation (validation, symbolic derivation,
//! hypothesis checks, evaluator optimisation) and emission (tokens,
//! prettyplease), i.e. `dalembert_codegen::generate`, for every built-in
//! model file.
//!
//! Run: `cargo bench --bench generator` (uses symbolica: nothing else that
//! uses it may run at the same time; it prints its banner once).

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};

fn generator(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    let mut g = c.benchmark_group("generate");
    g.sample_size(10);
    for file in files {
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        g.bench_function(&name, |b| {
            b.iter(|| dalembert_codegen::generate(&file).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, generator);
criterion_main!(benches);
