//! Arrays the host passes as pointer and length, read only after their
//! NULL and size checks.

/// True if `n` elements of `T` cannot be one array in memory: such a count is
/// refused before it reaches `slice::from_raw_parts` (whose contract it breaks).
pub fn too_many<T>(n: usize) -> bool {
    n > isize::MAX as usize / std::mem::size_of::<T>().max(1)
}

/// Slice from a C array; a null pointer is fine when `n` is 0.
///
/// # Safety
/// Unless `n` is 0, `p` must point to `n` readable elements; callers check
/// `p` for NULL and `n` with [`too_many`] first.
pub unsafe fn slice<'a, T>(p: *const T, n: usize) -> &'a [T] {
    if n == 0 || p.is_null() || too_many::<T>(n) {
        &[]
    } else {
        std::slice::from_raw_parts(p, n)
    }
}

/// # Safety
/// As for [`slice`], writable.
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> &'a mut [T] {
    if n == 0 || p.is_null() || too_many::<T>(n) {
        &mut []
    } else {
        std::slice::from_raw_parts_mut(p, n)
    }
}
