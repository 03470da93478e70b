//! One user of the symbolic engine at a time.
//!
//! Without a licence key symbolica runs in restricted mode: one thread per
//! user at a time, and a second process that touches it aborts. Two build
//! scripts, or the CLI during a build, could collide. Before its first
//! symbolic call a process takes an exclusive lock on a file of ours (with
//! the standard library's `File::lock`) and keeps it until it exits, so a
//! second process waits for the first instead of aborting. Within one
//! process the lock is taken once; callers must still not use the engine
//! from two threads at once.

use std::fs::{File, OpenOptions};
use std::path::PathBuf;
use std::sync::OnceLock;

static HELD: OnceLock<Result<File, String>> = OnceLock::new();

/// The lock file: one per user, in the system's temporary directory.
pub fn lock_path() -> PathBuf {
    let user = std::env::var("USER")
        .or_else(|_| std::env::var("USERNAME"))
        .unwrap_or_else(|_| "user".into());
    let user: String = user
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
        .collect();
    std::env::temp_dir().join(format!("dalembert-codegen-{user}.lock"))
}

/// Blocks until this process holds the lock; afterwards returns at once.
pub fn acquire() -> Result<(), String> {
    HELD.get_or_init(|| {
        let path = lock_path();
        let file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(|e| format!("cannot open the lock file {}: {e}", path.display()))?;
        file.lock()
            .map_err(|e| format!("cannot lock {}: {e}", path.display()))?;
        Ok(file)
    })
    .as_ref()
    .map(|_| ())
    .map_err(Clone::clone)
}
