//! Panics caught at the boundary: a panic in the core (on the caller's thread, in a rayon
//! worker it joins, or re-raised from a joined thread) becomes an error whose message says what
//! panicked and where to report it, so a caller (the Python binding) never unwinds.

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Where to report a caught panic.
const REPORT: &str = "this is a bug in latentrl; please report it with this message and the call that raised it";

/// The text of a panic payload (`panic!` with a literal or a formatted message), or a
/// placeholder for any other payload.
pub fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".to_string()
    }
}

/// The message of the error raised for a panic with `payload`: what it said, and where to
/// report it.
pub fn internal_message(payload: &(dyn Any + Send)) -> String {
    format!("internal error (Rust panic): {}; {REPORT}", panic_message(payload))
}

/// Runs `work`, the body of an exported function; a panic in it (on this thread, in a rayon
/// worker it joins, or re-raised from a joined thread) becomes the `Err` of
/// [`internal_message`] instead of unwinding.
pub fn catch<T, E>(work: impl FnOnce() -> Result<T, E>, on_panic: impl FnOnce(String) -> E) -> Result<T, E> {
    catch_unwind(AssertUnwindSafe(work)).unwrap_or_else(|payload| Err(on_panic(internal_message(&*payload))))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn caught<T>(work: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
        catch(work, |msg| msg)
    }

    #[test]
    fn results_pass_through() {
        assert_eq!(caught(|| Ok(3)), Ok(3));
        assert_eq!(caught::<()>(|| Err("bad input".into())), Err("bad input".into()));
    }

    #[test]
    fn panics_become_errors_with_message_and_hint() {
        let literal = caught::<()>(|| panic!("literal")).unwrap_err();
        assert!(
            literal.contains("literal") && literal.contains("please report"),
            "{literal}"
        );
        let formatted = caught::<()>(|| panic!("index {} out of range", 7)).unwrap_err();
        assert!(formatted.contains("index 7 out of range"), "{formatted}");
        let other = caught::<()>(|| std::panic::panic_any(42_u8)).unwrap_err();
        assert!(other.contains("unknown panic payload"), "{other}");
    }

    #[test]
    fn panics_in_rayon_and_joined_threads_are_caught() {
        use rayon::prelude::*;
        let msg = caught::<Vec<u32>>(|| {
            Ok((0..64_u32)
                .into_par_iter()
                .map(|i| if i == 33 { panic!("worker {i}") } else { i })
                .collect())
        })
        .unwrap_err();
        assert!(msg.contains("worker 33"), "{msg}");
        let msg = caught::<()>(|| {
            std::thread::scope(|s| s.spawn(|| panic!("thread")).join()).map_err(|p| std::panic::resume_unwind(p))
        })
        .unwrap_err();
        assert!(msg.contains("thread"), "{msg}");
    }
}
