//! The plugin's allocator: blocks of [`LARGE`] bytes or more are mapped from the system and
//! unmapped when freed; smaller ones go to the system allocator.
//!
//! Why: a script no table knows runs its analyses when it loads (modal analyses, stability
//! bisections), with dense matrices of up to tens of megabytes. glibc serves the first such
//! block with its own mapping, but freeing it raises its mmap threshold to that size, so the
//! next ones come from the arena of the thread that asked; `malloc_trim` does not give back a
//! non-main arena's top, so a host kept about 80 MB per analysed 1000-mass string resident
//! after the analyses had freed everything (docs/NOTES.md). Mapped directly, those blocks go
//! back to the system when the analysis frees them. Only the plugin's own allocations go
//! through here; the host's `malloc` is untouched.
//!
//! The audio thread never allocates, so the system calls here never run in `process()`.
//! Release builds only (`lib.rs`): debug builds may hold nice-plug's checking allocator.

use std::alloc::{GlobalAlloc, Layout, System};

/// The smallest block mapped directly: 256 KiB (a 180 × 180 matrix of `f64`).
pub const LARGE: usize = 256 * 1024;
const PAGE: usize = 4096;

/// Large blocks mapped, the rest from the system allocator.
pub struct LargeBlocks;

fn mapped(layout: Layout) -> bool {
    layout.size() >= LARGE && layout.align() <= PAGE
}

fn map(size: usize) -> *mut u8 {
    // SAFETY: an anonymous private mapping; no file, no fixed address.
    let p = unsafe {
        libc::mmap(
            std::ptr::null_mut(),
            size,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
            -1,
            0,
        )
    };
    if p == libc::MAP_FAILED {
        std::ptr::null_mut()
    } else {
        p.cast()
    }
}

// SAFETY: every block is either mapped here (size ≥ LARGE, alignment ≤ a page, which a mapping
// meets) and unmapped here with the same size, or handed to `System` and returned to it; the
// layout a block is freed with tells which, as `GlobalAlloc` guarantees it is the one it was
// allocated with.
unsafe impl GlobalAlloc for LargeBlocks {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if mapped(layout) {
            map(layout.size())
        } else {
            // SAFETY: the caller's layout, as `GlobalAlloc::alloc` requires.
            unsafe { System.alloc(layout) }
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if mapped(layout) {
            // Fresh anonymous pages are zero.
            map(layout.size())
        } else {
            // SAFETY: as for `alloc`.
            unsafe { System.alloc_zeroed(layout) }
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if mapped(layout) {
            // SAFETY: `ptr` was mapped by `map` with this size.
            unsafe {
                libc::munmap(ptr.cast(), layout.size());
            }
        } else {
            // SAFETY: `ptr` came from `System` with this layout.
            unsafe { System.dealloc(ptr, layout) }
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller guarantees `new_size` with this alignment is a valid layout.
        let new = unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
        match (mapped(layout), mapped(new)) {
            (false, false) => {
                // SAFETY: `ptr` came from `System` with `layout`.
                unsafe { System.realloc(ptr, layout, new_size) }
            }
            (true, true) => {
                // SAFETY: `ptr` is a mapping of `layout.size()` bytes made by `map`.
                let p = unsafe {
                    libc::mremap(ptr.cast(), layout.size(), new_size, libc::MREMAP_MAYMOVE)
                };
                if p == libc::MAP_FAILED {
                    std::ptr::null_mut()
                } else {
                    p.cast()
                }
            }
            _ => {
                // From one side of the threshold to the other: a new block, the bytes copied.
                // SAFETY: `new` is a valid non-zero layout (the caller's), and both blocks hold
                // at least the bytes copied.
                unsafe {
                    let p = self.alloc(new);
                    if !p.is_null() {
                        std::ptr::copy_nonoverlapping(ptr, p, layout.size().min(new_size));
                        self.dealloc(ptr, layout);
                    }
                    p
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_on_both_sides_of_the_threshold_keep_their_bytes() {
        let a = LargeBlocks;
        for (from, to) in [
            (100, 200),
            (1000, LARGE + 8),
            (LARGE, 3 * LARGE),
            (4 * LARGE, 10),
            (LARGE + 1, LARGE - 1),
        ] {
            let layout = Layout::from_size_align(from, 8).unwrap();
            // SAFETY: non-zero layouts; every block is freed with the layout it has.
            unsafe {
                let p = a.alloc_zeroed(layout);
                assert!(!p.is_null());
                let bytes = std::slice::from_raw_parts_mut(p, from);
                assert!(bytes.iter().all(|b| *b == 0), "zeroed: {from}");
                for (i, b) in bytes.iter_mut().enumerate() {
                    *b = (i % 251) as u8;
                }
                let q = a.realloc(p, layout, to);
                assert!(!q.is_null());
                let kept = std::slice::from_raw_parts(q, from.min(to));
                assert!(
                    kept.iter().enumerate().all(|(i, b)| *b == (i % 251) as u8),
                    "{from} → {to} keeps its bytes"
                );
                a.dealloc(q, Layout::from_size_align(to, 8).unwrap());
            }
        }
        // An alignment beyond a page stays with the system allocator.
        let big_align = Layout::from_size_align(LARGE, 2 * PAGE).unwrap();
        assert!(!mapped(big_align));
    }
}
