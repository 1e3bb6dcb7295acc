//! The live handles: every handle an engine passes is looked up here before it is touched, so a
//! null, freed, never-made or wrong-kind handle is an `INVALID_ARGUMENT`, not a use after free.

use crate::{Failure, Outcome};
use std::collections::HashSet;
use std::sync::Mutex;

/// What kind of object a handle is, so that a lighting passed as a context is refused.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub(crate) enum Kind {
    Context,
    Lighting,
    Shaders,
    Lightmaps,
    LutTables,
}

static LIVE: Mutex<Option<HashSet<(usize, Kind)>>> = Mutex::new(None);

fn with_live<R>(f: impl FnOnce(&mut HashSet<(usize, Kind)>) -> R) -> R {
    let mut live = LIVE.lock().unwrap_or_else(|p| p.into_inner());
    f(live.get_or_insert_with(HashSet::new))
}

/// Hands `value` out as a handle of `kind`.
pub(crate) fn make<T>(value: T, kind: Kind) -> *mut T {
    let ptr = Box::into_raw(Box::new(value));
    with_live(|live| live.insert((ptr as usize, kind)));
    ptr
}

/// Whether `ptr` is a live handle of `kind`, or the error naming `what` it was meant to be.
pub(crate) fn check<T>(ptr: *const T, kind: Kind, what: &str) -> Outcome {
    if ptr.is_null() {
        return Err(Failure::invalid(format!("{what} is null")));
    }
    if !with_live(|live| live.contains(&(ptr as usize, kind))) {
        return Err(Failure::invalid(format!(
            "{what} ({ptr:?}) is not a live {kind:?} handle: destroyed already, or never made \
             by histencil"
        )));
    }
    Ok(())
}

/// The object behind a live handle.
///
/// # Safety
/// No other reference to the object is in use: the header says each object's functions are
/// called from one thread at a time (the engine's external synchronisation, as Vulkan's).
pub(crate) unsafe fn get<'a, T>(ptr: *mut T, kind: Kind, what: &str) -> Outcome<&'a mut T> {
    check(ptr, kind, what)?;
    // SAFETY: `check` found it live: made by `make` from a Box and not yet taken; the caller
    // holds no other reference to it.
    Ok(unsafe { &mut *ptr })
}

/// Takes a live handle back, to free it: it is no longer live.
///
/// # Safety
/// As [`get`].
pub(crate) unsafe fn take<T>(ptr: *mut T, kind: Kind, what: &str) -> Outcome<Box<T>> {
    check(ptr, kind, what)?;
    with_live(|live| live.remove(&(ptr as usize, kind)));
    // SAFETY: made by `make` from a Box, live until the line above, and taken once.
    Ok(unsafe { Box::from_raw(ptr) })
}
