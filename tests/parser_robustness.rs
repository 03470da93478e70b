//! Thousands of mutated model files thrown at the parser and validator: each
//! must come back as a model or as located errors, never as a panic or a hang.
//! This stage does not use the symbolic engine.

use std::path::Path;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// The corpus to mutate: every good and bad model file in the repository.
fn corpus() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut texts = Vec::new();
    for dir in ["models", "tests/bad_models"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                texts.push(std::fs::read_to_string(path).unwrap());
            }
        }
    }
    texts.sort();
    texts
}

/// Fragments that are likely to matter to the parser.
const FRAGMENTS: &[&str] = &[
    "\"",
    "'''",
    "\"\"\"",
    "[",
    "]",
    "[[wall]]",
    "=",
    "{",
    "}",
    ",",
    "(",
    ")",
    "^",
    "/",
    "*",
    "-",
    "\n",
    "0.5",
    "1/0",
    "nan",
    "inf",
    "é",
    "θ",
    "sin(",
    "__",
    "_",
    "x_",
    "type",
    "v1",
    "m",
    "[definitions]\na = \"a\"\n",
    "\\u0000",
    "\\",
    "#",
    "\t",
    "99999999999999999999999",
];

#[derive(Debug, Clone)]
enum Mutation {
    Delete { at: usize, len: usize },
    Insert { at: usize, fragment: usize },
    SwapLines { a: usize, b: usize },
    DuplicateLine { at: usize },
    Truncate { at: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1usize..20).prop_map(|(at, len)| Mutation::Delete { at, len }),
        (any::<usize>(), 0..FRAGMENTS.len())
            .prop_map(|(at, fragment)| Mutation::Insert { at, fragment }),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines { a, b }),
        any::<usize>().prop_map(|at| Mutation::DuplicateLine { at }),
        any::<usize>().prop_map(|at| Mutation::Truncate { at }),
    ]
}

/// The nearest char boundary at or before `at`.
fn boundary(s: &str, at: usize) -> usize {
    let mut i = at % (s.len() + 1);
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut s = text.to_string();
    match m {
        Mutation::Delete { at, len } => {
            let a = boundary(&s, *at);
            let b = boundary(&s, (a + len).min(s.len()));
            s.replace_range(a..b.max(a), "");
        }
        Mutation::Insert { at, fragment } => {
            let a = boundary(&s, *at);
            s.insert_str(a, FRAGMENTS[*fragment]);
        }
        Mutation::SwapLines { a, b } => {
            let mut lines: Vec<&str> = text.lines().collect();
            if !lines.is_empty() {
                let n = lines.len();
                lines.swap(a % n, b % n);
            }
            s = lines.join("\n");
        }
        Mutation::DuplicateLine { at } => {
            let mut lines: Vec<&str> = text.lines().collect();
            if !lines.is_empty() {
                let i = at % lines.len();
                lines.insert(i, lines[i]);
            }
            s = lines.join("\n");
        }
        Mutation::Truncate { at } => {
            let a = boundary(&s, *at);
            s.truncate(a);
        }
    }
    s
}

#[test]
fn mutated_model_files_never_panic_or_hang() {
    let corpus = corpus();
    assert!(corpus.len() >= 20);
    let mut runner = TestRunner::new(Config {
        cases: 4000,
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (0..corpus.len(), proptest::collection::vec(mutation(), 1..6));
    let rejected = std::cell::Cell::new(0usize);
    runner
        .run(&strategy, |(i, mutations)| {
            let mut text = corpus[i].clone();
            for m in &mutations {
                text = apply(&text, m);
            }
            let start = Instant::now();
            let result = std::panic::catch_unwind(|| {
                dalembert_codegen::ir::parse(Path::new("mutated.toml"), &text)
            });
            prop_assert!(
                start.elapsed() < Duration::from_secs(2),
                "took {:?}",
                start.elapsed()
            );
            match result {
                Err(_) => prop_assert!(false, "the validator panicked on:\n{text}"),
                Ok(Err(errors)) => {
                    prop_assert!(!errors.errors.is_empty());
                    for d in &errors.errors {
                        prop_assert!(d.line >= 1 && d.col >= 1);
                        if let Some(span) = &d.span {
                            prop_assert!(span.start <= span.end && span.end <= text.len());
                        }
                    }
                    rejected.set(rejected.get() + 1);
                }
                Ok(Ok(_)) => {}
            }
            Ok(())
        })
        .unwrap();
    // The mutations do break files: most are rejected with errors.
    let rejected = rejected.get();
    assert!(
        rejected > 1000,
        "only {rejected} mutated files were rejected"
    );
}
