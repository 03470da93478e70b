//! Errors of every stage, each tied to a place in the model file.
//!
//! Stages return typed errors ([`ErrorKind`] inside [`Diagnostic`]); they are
//! rendered for people with miette only at the edges (build.rs, the CLI) by
//! [`ModelErrors::render`].

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// What is wrong with a model file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ErrorKind {
    /// The file is not valid TOML or does not have the model file's shape.
    #[error("{0}")]
    Toml(String),
    /// The file cannot be read.
    #[error("cannot read the model file: {0}")]
    Io(String),
    /// The model's generated file cannot be written.
    #[error("cannot generate the model's code: {0}")]
    Generation(String),
    /// The path is not a regular file (a FIFO or a device would block the
    /// reader or never end).
    #[error("the model file is not a regular file but {0}: a model file is read whole")]
    NotAFile(String),
    /// The file is larger than a model file may be.
    #[error("the model file is larger than {limit} bytes, the most a model file may be")]
    TooLarge {
        /// The limit, [`crate::ir::MAX_FILE_BYTES`].
        limit: u64,
    },
    /// A part of an expression that names nothing (numbers, pi, e and
    /// functions of them) is not a finite number, or is 0 where it divides.
    #[error("`{text}` is {what}")]
    UndefinedConstant {
        /// The part, as written.
        text: String,
        /// What is wrong with its value.
        what: String,
    },
    /// The file is not UTF-8 text (at the first byte that is not).
    #[error("the model file is not valid UTF-8 here")]
    NotUtf8,
    /// A name is not a usable identifier.
    #[error("`{name}` cannot be used as a name: {why}")]
    BadName {
        /// The name.
        name: String,
        /// Why not.
        why: String,
    },
    /// A name is declared twice.
    #[error("`{name}` is declared twice: it is already a {first}")]
    Duplicate {
        /// The name.
        name: String,
        /// What it was declared as first.
        first: &'static str,
    },
    /// An expression uses a name that is not declared.
    #[error("unknown name `{name}`: declare it as a parameter, coordinate, velocity or definition")]
    UnknownName {
        /// The name.
        name: String,
    },
    /// An expression calls a function that models may not use.
    #[error(
        "unknown function `{name}`: models may use {}",
        crate::ir::Function::listed()
    )]
    UnknownFunction {
        /// The function's name.
        name: String,
    },
    /// An expression is malformed.
    #[error("malformed expression: {0}")]
    Syntax(String),
    /// A model exceeds a limit that keeps derivation time and memory
    /// bounded.
    #[error("too large: {0}")]
    Limit(String),
    /// A parameter value is not an exact finite number.
    #[error("parameter `{name}`: {why}")]
    BadParameter {
        /// The parameter.
        name: String,
        /// What is wrong.
        why: String,
    },
    /// A required part of the model is missing, or two parts contradict.
    #[error("{0}")]
    Structure(String),
    /// Definitions refer to each other in a cycle.
    #[error("definition `{0}` refers to itself (directly or through other definitions)")]
    Cycle(String),
    /// T is not a quadratic form in the velocities.
    #[error("the kinetic energy is not a quadratic form in the velocities: {0}")]
    NotQuadratic(String),
    /// A row (a constraint, a contact or normal-velocity row, a rate given
    /// at the start) is not linear in the velocities.
    #[error("this row is not linear in the velocities: {0}")]
    NotLinear(String),
    /// A velocity occurs other than polynomially.
    #[error(
        "`{name}` depends on the velocities and is {place}: velocities may occur only in sums, products and whole non-negative powers (the kinetic energy is a quadratic form in them, every constraint row linear)"
    )]
    VelocityNotPolynomial {
        /// The velocity, or the definition that depends on one.
        name: String,
        /// Where it occurs, in words.
        place: String,
    },
    /// The potential depends on velocities.
    #[error("the potential depends on the velocity `{0}`")]
    VelocityInPotential(String),
    /// A holonomic constraint h(q) = 0 depends on a velocity.
    #[error(
        "a holonomic constraint depends on the velocity `{0}`: declare velocity-level constraints under `constraints`"
    )]
    VelocityInHolonomic(String),
    /// A surface function depends on velocities.
    #[error("wall `{wall}`: the surface function depends on the velocity `{velocity}`")]
    VelocityInSurface {
        /// The wall.
        wall: String,
        /// The velocity.
        velocity: String,
    },
    /// G is not positive definite.
    #[error("the mass matrix G is not positive definite at {at}")]
    NotPositiveDefinite {
        /// The sample point.
        at: String,
    },
    /// A paper hypothesis fails for a wall.
    #[error("wall `{wall}` breaks the paper's hypothesis {condition} (for {at})")]
    Hypothesis {
        /// The wall.
        wall: String,
        /// Which condition, in the paper's terms.
        condition: String,
        /// The sample point.
        at: String,
    },
    /// An expression has no finite real value (a division by zero, the
    /// logarithm of 0, the square root of a negative number).
    #[error("the expression is undefined: {0}")]
    Domain(String),
    /// The symbolic engine reported a failure.
    #[error("symbolic derivation failed: {0}")]
    Symbolic(String),
}

/// One error with its place in the model file.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    /// What is wrong.
    pub kind: ErrorKind,
    /// Byte range in the file, when known.
    pub span: Option<Range<usize>>,
    /// 1-based line and column of the span's start (1:1 when unknown).
    pub line: usize,
    /// 1-based column, in characters.
    pub col: usize,
}

/// All errors found in one model file.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelErrors {
    /// The model file.
    pub file: PathBuf,
    /// Its text (empty when it could not be read).
    pub source: String,
    /// The errors, in file order.
    pub errors: Vec<Diagnostic>,
}

impl fmt::Display for ModelErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.errors.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(
                f,
                "{}:{}:{}: error: {}",
                self.file.display(),
                d.line,
                d.col,
                d.kind
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for ModelErrors {}

impl ModelErrors {
    /// The errors as people read them: each with its file:line:col, the
    /// offending line and a marker under the offending text.
    pub fn render(&self) -> String {
        use miette::{GraphicalReportHandler, GraphicalTheme, NamedSource};
        let handler = GraphicalReportHandler::new_themed(GraphicalTheme::unicode_nocolor());
        let mut out = String::new();
        for d in &self.errors {
            // miette cannot draw a marker far out on a very long line (it
            // panics past column 65535): such errors keep their
            // file:line:col but are shown without the snippet.
            let drawable = d.span.as_ref().filter(|s| {
                let line = self
                    .source
                    .get(..s.start)
                    .map_or(0, |b| b.rfind('\n').map_or(0, |i| i + 1));
                let end = self.source[line..]
                    .find('\n')
                    .map_or(self.source.len(), |i| line + i);
                end - line <= MAX_DRAWN_LINE && s.end <= self.source.len()
            });
            let report = Rendered {
                message: format!("{}:{}:{}: {}", self.file.display(), d.line, d.col, d.kind),
                source: NamedSource::new(self.file.display().to_string(), self.source.clone()),
                span: drawable.map(|s| (s.start, s.end - s.start).into()),
            };
            let _ = handler.render_report(&mut out, &report);
        }
        out
    }
}

/// Longest line (in bytes) whose errors are drawn with a snippet.
const MAX_DRAWN_LINE: usize = 4096;

#[derive(Debug)]
struct Rendered {
    message: String,
    source: miette::NamedSource<String>,
    span: Option<miette::SourceSpan>,
}

impl fmt::Display for Rendered {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Rendered {}

impl miette::Diagnostic for Rendered {
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.span.map(|_| &self.source as &dyn miette::SourceCode)
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        let span = self.span?;
        Some(Box::new(std::iter::once(
            miette::LabeledSpan::new_with_span(Some("here".into()), span),
        )))
    }
}

/// Proof that an error was recorded. Only [`Collector::error`] makes one, so
/// a stage that fails with `Err(Reported)` has always said why: a failure
/// with no diagnostic cannot be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reported(());

/// Collects errors for one file (the `Ctxt` pattern): every stage adds what it
/// finds and the caller decides at the end whether to go on.
#[derive(Debug)]
pub struct Collector {
    file: PathBuf,
    source: String,
    errors: Vec<Diagnostic>,
}

impl Collector {
    /// A collector for `file` with text `source`.
    pub fn new(file: &Path, source: &str) -> Self {
        Self {
            file: file.to_path_buf(),
            source: source.to_string(),
            errors: Vec::new(),
        }
    }

    /// Records an error at `span` (the proof that it was recorded is
    /// returned, for stages that stop here).
    pub fn error(&mut self, kind: ErrorKind, span: Option<Range<usize>>) -> Reported {
        let (line, col) = span
            .as_ref()
            .map(|s| line_col(&self.source, s.start))
            .unwrap_or((1, 1));
        self.errors.push(Diagnostic {
            kind,
            span,
            line,
            col,
        });
        Reported(())
    }

    /// Whether anything was recorded.
    pub fn has_errors(&self) -> bool {
        !self.errors.is_empty()
    }

    /// `Err` with everything recorded, or `Ok(value)` when nothing was.
    pub fn finish<T>(self, value: T) -> Result<T, ModelErrors> {
        self.conclude(Ok(value))
    }

    /// The end of a stage: `Ok` when it succeeded and nothing was recorded,
    /// else everything recorded, which is never empty (a failure carries a
    /// [`Reported`]).
    pub fn conclude<T>(self, result: Result<T, Reported>) -> Result<T, ModelErrors> {
        match result {
            Ok(value) if self.errors.is_empty() => Ok(value),
            _ => Err(self.into_errors()),
        }
    }

    /// Everything recorded, sorted by position.
    pub fn into_errors(mut self) -> ModelErrors {
        self.errors
            .sort_by_key(|d| (d.line, d.col, d.span.as_ref().map(|s| s.end)));
        ModelErrors {
            file: self.file,
            source: self.source,
            errors: self.errors,
        }
    }
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|l| l.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}
