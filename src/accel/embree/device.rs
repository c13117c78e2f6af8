//! The Embree device (`rtcNewDevice(3)`), its error callback, and the error check that
//! turns Embree errors into [`EmbreeError`]s.
use std::ffi::{c_char, c_void, CStr, CString};
use std::sync::{Arc, Mutex, MutexGuard};

use super::sys;
use super::{EmbreeError, SceneBuilder};

/// An Embree device (`rtcNewDevice(3)`), released on drop (`rtcReleaseDevice(3)`).
///
/// The device owns the error callback registered with `rtcSetDeviceErrorFunction(3)`;
/// builder and commit calls check `rtcGetDeviceError(3)` and return
/// [`EmbreeError::Device`] with the callback's message. Committed [`super::Scene`]s keep
/// the device alive through a reference count, so the `Device` itself may be dropped first.
pub struct Device {
    pub(crate) inner: Arc<DeviceInner>,
}

/// The shared part of a [`Device`]: the Embree handle, the error slot the callback writes
/// into, and the lock that serialises every non-query Embree call made through it.
pub(crate) struct DeviceInner {
    raw: sys::RTCDevice,
    /// Lives as long as the Embree device: `rtcReleaseDevice` runs in `Drop` before the
    /// fields are dropped, and no scene or geometry of this device outlives `DeviceInner`
    /// (committed scenes hold an `Arc`, builders borrow the `Device`).
    errors: ErrorSlot,
    /// Embree's man pages say API calls touching the same object are not thread-safe
    /// unless stated otherwise (only attaching geometry and ray queries are). All
    /// building, committing and releasing through this device happens under this lock,
    /// which is what makes `Device: Sync` sound and also lets the error slot hold just
    /// the error of the call in progress. Ray queries never take it.
    lock: Mutex<()>,
}

/// The first error reported through the callback since the last check.
#[derive(Default)]
struct ErrorSlot(Mutex<Option<(sys::RTCError, String)>>);

impl ErrorSlot {
    fn record(&self, code: sys::RTCError, message: String) {
        let mut slot = self.0.lock().unwrap_or_else(|e| e.into_inner());
        // Keep the first error, like rtcGetDeviceError: later ones are usually fallout.
        if slot.is_none() {
            *slot = Some((code, message));
        }
    }
    fn take(&self) -> Option<(sys::RTCError, String)> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).take()
    }
}

/// The `RTCErrorFunction` registered for every heron device.
///
/// Embree calls it synchronously, on the thread whose API call failed, with the
/// `userPtr` given at registration (a `*const ErrorSlot`).
unsafe extern "C" fn error_callback(
    user_ptr: *mut c_void,
    code: sys::RTCError,
    str: *const c_char,
) {
    let message = if str.is_null() {
        String::new()
    } else {
        // SAFETY: Embree passes a NUL-terminated string valid for the call.
        unsafe { CStr::from_ptr(str) }
            .to_string_lossy()
            .into_owned()
    };
    // SAFETY: `user_ptr` is the address of the `ErrorSlot` inside the `DeviceInner`
    // registered in `Device::new`; it stays valid until the device is released (see
    // `DeviceInner::errors`), and `ErrorSlot` is only used through shared references.
    let slot = unsafe { &*(user_ptr as *const ErrorSlot) };
    slot.record(code, message);
}

// SAFETY: `raw` is only used for Embree calls made under `lock` (and, in `Drop`, with
// exclusive access); the error slot is a Mutex. Embree devices are not tied to the thread
// that created them.
unsafe impl Send for DeviceInner {}
// SAFETY: see `Send`; every shared-access path to `raw` goes through `lock`.
unsafe impl Sync for DeviceInner {}

impl Drop for DeviceInner {
    fn drop(&mut self) {
        // SAFETY: `raw` came from rtcNewDevice and this is its only release; no scene or
        // geometry handle made by heron from it is alive any more (see `errors`).
        unsafe { sys::rtcReleaseDevice(self.raw) }
    }
}

/// Proof that the device lock is held; the only way to reach the raw device handle for
/// building calls.
pub(crate) struct Locked<'a> {
    inner: &'a DeviceInner,
    _guard: MutexGuard<'a, ()>,
}

impl Locked<'_> {
    pub(crate) fn raw(&self) -> sys::RTCDevice {
        self.inner.raw
    }

    /// Collects the error state after the Embree calls described by `what`:
    /// `rtcGetDeviceError(3)` (this thread's first error since the last check) plus the
    /// message the callback recorded.
    pub(crate) fn check(&self, what: &str) -> Result<(), EmbreeError> {
        // SAFETY: `raw` is a live device; rtcGetDeviceError only reads and clears this
        // thread's error code.
        let code = unsafe { sys::rtcGetDeviceError(self.inner.raw) };
        let recorded = self.inner.errors.take();
        match (code, recorded) {
            (sys::RTC_ERROR_NONE, None) => Ok(()),
            (code, Some((cb_code, message))) => {
                let code = if code == sys::RTC_ERROR_NONE {
                    cb_code
                } else {
                    code
                };
                Err(EmbreeError::Device {
                    code: sys::error_name(code).to_string(),
                    message: format!("{what}: {message}"),
                })
            }
            (code, None) => Err(EmbreeError::Device {
                code: sys::error_name(code).to_string(),
                message: format!("{what} failed"),
            }),
        }
    }
}

impl DeviceInner {
    pub(crate) fn lock(&self) -> Locked<'_> {
        Locked {
            inner: self,
            _guard: self.lock.lock().unwrap_or_else(|e| e.into_inner()),
        }
    }
}

impl Device {
    /// Creates a device; `config` is Embree's configuration string (may be empty), e.g.
    /// `"threads=4"` or `"verbose=1"`; see `rtcNewDevice(3)`. Unknown options are
    /// ignored by Embree 3.
    pub fn new(config: &str) -> Result<Device, EmbreeError> {
        let c_config = CString::new(config).map_err(|_| {
            EmbreeError::Other(format!("device config {config:?} contains a NUL byte"))
        })?;
        // SAFETY: `c_config` is a valid NUL-terminated string for the call.
        let raw = unsafe { sys::rtcNewDevice(c_config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: rtcGetDeviceError(NULL) is how rtcNewDevice failures are queried.
            let code = unsafe { sys::rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(EmbreeError::Device {
                code: sys::error_name(code).to_string(),
                message: format!("rtcNewDevice({config:?}) failed"),
            });
        }
        let inner = Arc::new(DeviceInner {
            raw,
            errors: ErrorSlot::default(),
            lock: Mutex::new(()),
        });
        let locked = inner.lock();
        let user_ptr = &inner.errors as *const ErrorSlot as *mut c_void;
        // SAFETY: `raw` is live; the callback matches RTCErrorFunction; `user_ptr` points
        // into the Arc's allocation, which outlives the device (see `DeviceInner`).
        unsafe { sys::rtcSetDeviceErrorFunction(raw, Some(error_callback), user_ptr) };
        locked.check("rtcSetDeviceErrorFunction")?;
        drop(locked);
        Ok(Device { inner })
    }

    /// Embree's version as (major, minor, patch), from `rtcGetDeviceProperty(3)`.
    pub fn version(&self) -> (u32, u32, u32) {
        let locked = self.inner.lock();
        let get = |prop| {
            // SAFETY: live device, valid property id.
            let v = unsafe { sys::rtcGetDeviceProperty(locked.raw(), prop) };
            u32::try_from(v).unwrap_or(0)
        };
        (
            get(sys::RTC_DEVICE_PROPERTY_VERSION_MAJOR),
            get(sys::RTC_DEVICE_PROPERTY_VERSION_MINOR),
            get(sys::RTC_DEVICE_PROPERTY_VERSION_PATCH),
        )
    }

    /// Starts a new scene (`rtcNewScene(3)`). If Embree cannot create it, the error is
    /// reported by the builder's first method call (and by `commit`).
    pub fn scene_builder(&self) -> SceneBuilder<'_> {
        SceneBuilder::new(self)
    }
}

impl std::fmt::Debug for Device {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Device").finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The callback path: an invalid argument makes Embree call `error_callback`, and
    /// `check` returns the code plus Embree's message; the next check is clean again.
    #[test]
    fn embree_errors_reach_check_with_their_message() {
        let device = Device::new("").unwrap();
        let locked = device.inner.lock();
        // SAFETY: live device; the scene is released below; lock held.
        let scene = unsafe { sys::rtcNewScene(locked.raw()) };
        assert!(!scene.is_null());
        // SAFETY: live scene; 77 is not a build quality, which Embree reports as an error.
        unsafe { sys::rtcSetSceneBuildQuality(scene, 77) };
        match locked.check("rtcSetSceneBuildQuality") {
            Err(EmbreeError::Device { code, message }) => {
                assert!(code.starts_with("RTC_ERROR_"), "{code}");
                assert!(message.contains("rtcSetSceneBuildQuality: "), "{message}");
                assert!(message.contains("build quality"), "{message}");
            }
            other => panic!("expected a device error, got {other:?}"),
        }
        assert!(locked.check("nothing").is_ok());
        // SAFETY: releases the scene created above, once.
        unsafe { sys::rtcReleaseScene(scene) };
        assert!(locked.check("rtcReleaseScene").is_ok());
    }
}
