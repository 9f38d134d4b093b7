//! Slot storage behind [`Handle`]s, shared by every backend.

use super::desc::Handle;
use super::BackendError;

/// A free-list of resource slots; a slot's generation increases when it is freed.
pub(crate) struct Pool<R> {
    slots: Vec<(u32, Option<R>)>,
    free: Vec<u32>,
    kind: &'static str,
}

impl<R> Pool<R> {
    pub(crate) fn new(kind: &'static str) -> Self {
        Self {
            slots: Vec::new(),
            free: Vec::new(),
            kind,
        }
    }

    pub(crate) fn insert<T>(&mut self, resource: R) -> Handle<T> {
        if let Some(index) = self.free.pop() {
            let slot = &mut self.slots[index as usize];
            slot.1 = Some(resource);
            Handle::new(index, slot.0)
        } else {
            self.slots.push((0, Some(resource)));
            Handle::new(self.slots.len() as u32 - 1, 0)
        }
    }

    pub(crate) fn get<T>(&self, handle: Handle<T>) -> Result<&R, BackendError> {
        match self.slots.get(handle.index as usize) {
            Some((generation, Some(r))) if *generation == handle.generation => Ok(r),
            _ => Err(BackendError::InvalidHandle {
                kind: self.kind,
                handle: format!("{handle:?}"),
            }),
        }
    }

    pub(crate) fn remove<T>(&mut self, handle: Handle<T>) -> Result<R, BackendError> {
        self.get(handle)?;
        let slot = &mut self.slots[handle.index as usize];
        slot.0 = slot.0.wrapping_add(1);
        self.free.push(handle.index);
        Ok(slot.1.take().expect("checked by get"))
    }

    /// Takes every live resource out (for teardown).
    pub(crate) fn drain(&mut self) -> impl Iterator<Item = R> + '_ {
        self.free.clear();
        self.slots.drain(..).filter_map(|(_, r)| r)
    }

    /// Number of live resources.
    pub(crate) fn len(&self) -> usize {
        self.slots.iter().filter(|(_, r)| r.is_some()).count()
    }
}
