//! Ctrl-C and SIGTERM, one handler for the whole process (a process can install only
//! one): a command may take the first signal for itself (identify stops its search
//! and still writes the best result); otherwise — or at a second signal — the
//! temporary files being written are deleted and the process exits with 130.

use std::sync::Mutex;

/// What a command does with a signal: `true` if it handled it and the process goes on.
type Hook = Box<dyn Fn() -> bool + Send>;

static HOOK: Mutex<Option<Hook>> = Mutex::new(None);

/// Installs the handler (once, at start).
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        let handled = HOOK
            .lock()
            .map(|h| h.as_ref().is_some_and(|f| f()))
            .unwrap_or(false);
        if !handled {
            rtid::io::atomic::remove_unfinished();
            std::process::exit(130);
        }
    });
}

/// Lets the running command handle the signals first.
pub fn on_interrupt(f: impl Fn() -> bool + Send + 'static) {
    if let Ok(mut h) = HOOK.lock() {
        *h = Some(Box::new(f));
    }
}
