//! A counting global allocator, so `radiosity bench` can report the peak heap of each case
//! and the bytes per element (memory must stay linear in elements).
//!
//! It forwards to the system allocator and keeps two atomics (bytes live, highest seen since
//! the last reset): one relaxed add per allocation, nothing measurable next to a solve.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator with live and peak byte counts.
pub struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(bytes: usize) {
    let now = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

// SAFETY: every call forwards to `System` with the caller's layout and pointer unchanged;
// the counters do not touch the memory.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as is (see the impl).
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as is (see the impl).
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded as is (see the impl).
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded as is (see the impl).
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
            grew(new_size);
        }
        p
    }
}

/// Has glibc's allocator keep the memory a program frees for its next allocations rather
/// than hand it back to the system at once: every allocation over its mmap threshold (at
/// most 32 MB) was mapped on its own and unmapped when freed, so the next table of that size
/// took fresh pages, each zeroed by the kernel on first touch. Meshing and setting up a
/// 1.1 M-triangle scene made 1.18 M page faults for a 1.79 GB peak, 4.7–8.8 s of system
/// time; with this, 0.47 M faults, 3.8–4.2 s, and a 1.90 GB peak. Call before any thread
/// starts.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` only sets the allocator's parameters; no allocation is in flight on
    // another thread yet.
    unsafe {
        // No allocation mapped on its own: all come from the heap, which reuses what is freed...
        libc::mallopt(libc::M_MMAP_MAX, 0);
        // ...and gives its free top back to the system only past 2 GB.
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
    }
}

/// Heap bytes live now.
pub fn live() -> usize {
    LIVE.load(Ordering::Relaxed)
}

/// Starts a new peak measurement from the bytes live now.
pub fn reset_peak() {
    PEAK.store(live(), Ordering::Relaxed);
}

/// Highest heap bytes live since the last [`reset_peak`].
pub fn peak() -> usize {
    PEAK.load(Ordering::Relaxed)
}
