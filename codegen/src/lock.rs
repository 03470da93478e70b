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

use std::fs::{File, OpenOptions, TryLockError};
use std::io::Write as _;
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

/// Blocks until this process holds the lock (saying on standard error whom
/// it waits for, when it has to); afterwards returns at once.
pub fn acquire() -> Result<(), String> {
    HELD.get_or_init(|| {
        let path = lock_path();
        let file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(|e| format!("cannot open the lock file {}: {e}", path.display()))?;
        let cannot = |e: std::io::Error| format!("cannot lock {}: {e}", path.display());
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let holder = std::fs::read_to_string(&path).unwrap_or_default();
                let holder = holder.trim();
                eprintln!(
                    "waiting for the symbolic engine: {} holds {} (without a licence key symbolica serves one process per user)",
                    if holder.is_empty() { "another process" } else { holder },
                    path.display()
                );
                file.lock().map_err(cannot)?;
            }
            Err(TryLockError::Error(e)) => return Err(cannot(e)),
        }
        // Say who holds it, for whoever waits next.
        let mut file = file;
        let me = format!(
            "process {} ({})",
            std::process::id(),
            std::env::args().collect::<Vec<_>>().join(" ")
        );
        let _ = file.set_len(0).and_then(|()| file.write_all(me.as_bytes()));
        // The first symbols of ours, at the same point in every process.
        crate::derive::make_places();
        Ok(file)
    })
    .as_ref()
    .map(|_| ())
    .map_err(Clone::clone)
}
