//! The one way robowire takes a lock: a lock a thread panicked while holding is taken anyway,
//! because every robowire lock guards plain data whose invariants hold between statements. None
//! of these is ever called on a stream thread.

use std::sync::{Condvar, Mutex, MutexGuard, PoisonError, RwLock, RwLockReadGuard, RwLockWriteGuard};
use std::time::Duration;

/// Locks `mutex`.
pub fn lock<T: ?Sized>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Locks `rwlock` for reading.
pub fn read<T: ?Sized>(rwlock: &RwLock<T>) -> RwLockReadGuard<'_, T> {
    rwlock.read().unwrap_or_else(PoisonError::into_inner)
}

/// Locks `rwlock` for writing.
pub fn write<T: ?Sized>(rwlock: &RwLock<T>) -> RwLockWriteGuard<'_, T> {
    rwlock.write().unwrap_or_else(PoisonError::into_inner)
}

/// Waits on `condvar` with `guard` while `condition` holds, at most `timeout`; the guard again.
pub fn wait_timeout_while<'a, T>(
    condvar: &Condvar,
    guard: MutexGuard<'a, T>,
    timeout: Duration,
    condition: impl FnMut(&mut T) -> bool,
) -> MutexGuard<'a, T> {
    match condvar.wait_timeout_while(guard, timeout, condition) {
        Ok((guard, _)) => guard,
        Err(poisoned) => poisoned.into_inner().0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_poisoned_lock_is_taken_with_its_data() {
        let mutex = Mutex::new(7);
        let rwlock = RwLock::new(8);
        std::thread::scope(|s| {
            let _ = s
                .spawn(|| {
                    let _m = lock(&mutex);
                    let _w = write(&rwlock);
                    panic!("poison both");
                })
                .join();
        });
        assert!(mutex.is_poisoned() && rwlock.is_poisoned());
        assert_eq!(*lock(&mutex), 7);
        assert_eq!(*read(&rwlock), 8);
        *write(&rwlock) = 9;
        assert_eq!(*read(&rwlock), 9);
        let condvar = Condvar::new();
        let guard = wait_timeout_while(&condvar, lock(&mutex), Duration::ZERO, |v| *v == 7);
        assert_eq!(*guard, 7);
    }
}
