//! Hand-written declarations for exactly the part of Embree's C API that heron uses.
//!
//! Names, field names and values follow the headers (`/usr/include/embree3/rtcore*.h` on
//! Debian 12) so that they can be checked against them line by line; the man pages in
//! `libembree-dev` (`man rtcIntersect1` …) are the API reference cited below.
//!
//! Embree 3 and Embree 4 differ, for what heron uses, only in
//! * the ray-query functions: Embree 3 takes an `RTCIntersectContext*` before the ray,
//!   Embree 4 drops the context and takes an optional arguments struct after the ray;
//! * `RTCHit`/`RTCHit8`: Embree 4.3 may append `instPrimID[RTC_MAX_INSTANCE_LEVEL_COUNT]`.
//!
//! Both live behind the single `cfg(heron_embree4)` that build.rs sets after probing the
//! installed headers; the rest of heron only calls [`intersect1`], [`occluded1`],
//! [`intersect8`], [`occluded8`], [`RTCHit::invalid`] and [`RTCHit8::invalid`], which have
//! the same signatures for both. Both are tested: Debian's Embree 3.13.5, and Embree 4.4
//! from the pinned `embreex` wheel (scripts/test.sh). The Embree 4 branch passes NULL
//! arguments, so the coherence hint is dropped there.
//!
//! C enums are declared as `u32` type aliases with constants, never as Rust enums, so an
//! unexpected value coming back from C (e.g. a new `RTCError`) cannot be undefined
//! behaviour. On x86_64 Linux these C enums are 4 bytes (checked with a C program).
#![allow(non_camel_case_types, non_snake_case, dead_code)]

use std::ffi::{c_char, c_void};

// ---------------------------------------------------------------------------------------
// Handles (rtcore_device.h, rtcore_scene.h, rtcore_geometry.h)

#[repr(C)]
pub struct RTCDeviceTy {
    _opaque: [u8; 0],
}
#[repr(C)]
pub struct RTCSceneTy {
    _opaque: [u8; 0],
}
#[repr(C)]
pub struct RTCGeometryTy {
    _opaque: [u8; 0],
}
pub type RTCDevice = *mut RTCDeviceTy;
pub type RTCScene = *mut RTCSceneTy;
pub type RTCGeometry = *mut RTCGeometryTy;

// ---------------------------------------------------------------------------------------
// Enums (as constants)

/// `RTC_INVALID_GEOMETRY_ID` = `(unsigned int)-1` (rtcore_common.h).
pub const RTC_INVALID_GEOMETRY_ID: u32 = u32::MAX;

/// `enum RTCError` (rtcore_device.h).
pub type RTCError = u32;
pub const RTC_ERROR_NONE: RTCError = 0;
pub const RTC_ERROR_UNKNOWN: RTCError = 1;
pub const RTC_ERROR_INVALID_ARGUMENT: RTCError = 2;
pub const RTC_ERROR_INVALID_OPERATION: RTCError = 3;
pub const RTC_ERROR_OUT_OF_MEMORY: RTCError = 4;
pub const RTC_ERROR_UNSUPPORTED_CPU: RTCError = 5;
pub const RTC_ERROR_CANCELLED: RTCError = 6;

/// `enum RTCDeviceProperty` (rtcore_device.h), only the entries heron reads.
pub type RTCDeviceProperty = u32;
pub const RTC_DEVICE_PROPERTY_VERSION: RTCDeviceProperty = 0;
pub const RTC_DEVICE_PROPERTY_VERSION_MAJOR: RTCDeviceProperty = 1;
pub const RTC_DEVICE_PROPERTY_VERSION_MINOR: RTCDeviceProperty = 2;
pub const RTC_DEVICE_PROPERTY_VERSION_PATCH: RTCDeviceProperty = 3;

/// `enum RTCGeometryType` (rtcore_geometry.h).
pub type RTCGeometryType = u32;
pub const RTC_GEOMETRY_TYPE_TRIANGLE: RTCGeometryType = 0;
pub const RTC_GEOMETRY_TYPE_SPHERE_POINT: RTCGeometryType = 50;

/// `enum RTCBufferType` (rtcore_geometry.h).
pub type RTCBufferType = u32;
pub const RTC_BUFFER_TYPE_INDEX: RTCBufferType = 0;
pub const RTC_BUFFER_TYPE_VERTEX: RTCBufferType = 1;

/// `enum RTCFormat` (rtcore_common.h): `RTC_FORMAT_UINT = 0x5001`, `RTC_FORMAT_FLOAT =
/// 0x9001`, each followed by its 2-, 3-, 4-component variants.
pub type RTCFormat = u32;
pub const RTC_FORMAT_UINT3: RTCFormat = 0x5003;
pub const RTC_FORMAT_FLOAT3: RTCFormat = 0x9003;
pub const RTC_FORMAT_FLOAT4: RTCFormat = 0x9004;

/// `enum RTCSceneFlags` (rtcore_scene.h).
pub type RTCSceneFlags = u32;
pub const RTC_SCENE_FLAG_NONE: RTCSceneFlags = 0;
pub const RTC_SCENE_FLAG_ROBUST: RTCSceneFlags = 1 << 2;

/// `enum RTCBuildQuality` (rtcore_common.h).
pub type RTCBuildQuality = u32;
pub const RTC_BUILD_QUALITY_LOW: RTCBuildQuality = 0;
pub const RTC_BUILD_QUALITY_MEDIUM: RTCBuildQuality = 1;
pub const RTC_BUILD_QUALITY_HIGH: RTCBuildQuality = 2;

/// `typedef void (*RTCErrorFunction)(void* userPtr, enum RTCError code, const char* str)`.
pub type RTCErrorFunction =
    Option<unsafe extern "C" fn(user_ptr: *mut c_void, code: RTCError, message: *const c_char)>;

/// Name of an error code as spelled in the header.
pub fn error_name(code: RTCError) -> &'static str {
    match code {
        RTC_ERROR_NONE => "RTC_ERROR_NONE",
        RTC_ERROR_UNKNOWN => "RTC_ERROR_UNKNOWN",
        RTC_ERROR_INVALID_ARGUMENT => "RTC_ERROR_INVALID_ARGUMENT",
        RTC_ERROR_INVALID_OPERATION => "RTC_ERROR_INVALID_OPERATION",
        RTC_ERROR_OUT_OF_MEMORY => "RTC_ERROR_OUT_OF_MEMORY",
        RTC_ERROR_UNSUPPORTED_CPU => "RTC_ERROR_UNSUPPORTED_CPU",
        RTC_ERROR_CANCELLED => "RTC_ERROR_CANCELLED",
        _ => "RTC_ERROR_<unknown code>",
    }
}

// ---------------------------------------------------------------------------------------
// Structs (rtcore_common.h, rtcore_ray.h). `RTC_MAX_INSTANCE_LEVEL_COUNT` is 1 and
// `RTC_MIN_WIDTH` is 0 in Debian's build; build.rs refuses other configurations.

/// `struct RTC_ALIGN(16) RTCBounds` (rtcore_common.h).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCBounds {
    pub lower_x: f32,
    pub lower_y: f32,
    pub lower_z: f32,
    pub align0: f32,
    pub upper_x: f32,
    pub upper_y: f32,
    pub upper_z: f32,
    pub align1: f32,
}

/// `struct RTC_ALIGN(16) RTCRay` (rtcore_ray.h); identical in Embree 3 and 4.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRay {
    pub org_x: f32,
    pub org_y: f32,
    pub org_z: f32,
    pub tnear: f32,
    pub dir_x: f32,
    pub dir_y: f32,
    pub dir_z: f32,
    pub time: f32,
    pub tfar: f32,
    pub mask: u32,
    pub id: u32,
    pub flags: u32,
}

/// `struct RTC_ALIGN(16) RTCHit` (rtcore_ray.h).
///
/// Embree 4.3 appends `instPrimID[]` when built with `RTC_GEOMETRY_INSTANCE_ARRAY`; the
/// Embree 4 variant always has it: Embree only writes fields it knows, so a struct with
/// an unused trailing field is safe either way, while a struct that is too short is not.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug)]
pub struct RTCHit {
    pub Ng_x: f32,
    pub Ng_y: f32,
    pub Ng_z: f32,
    pub u: f32,
    pub v: f32,
    pub primID: u32,
    pub geomID: u32,
    pub instID: [u32; 1],
    #[cfg(heron_embree4)]
    pub instPrimID: [u32; 1],
}

impl RTCHit {
    /// A hit record as `rtcIntersect1(3)` requires it before the call: `geomID` and the
    /// instance IDs set to `RTC_INVALID_GEOMETRY_ID`.
    pub const fn invalid() -> RTCHit {
        RTCHit {
            Ng_x: 0.0,
            Ng_y: 0.0,
            Ng_z: 0.0,
            u: 0.0,
            v: 0.0,
            primID: RTC_INVALID_GEOMETRY_ID,
            geomID: RTC_INVALID_GEOMETRY_ID,
            instID: [RTC_INVALID_GEOMETRY_ID],
            #[cfg(heron_embree4)]
            instPrimID: [RTC_INVALID_GEOMETRY_ID],
        }
    }
}

/// `struct RTCRayHit` (rtcore_ray.h): 16-byte aligned through its members.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCRayHit {
    pub ray: RTCRay,
    pub hit: RTCHit,
}

/// Declares the packet types of one width W (rtcore_ray.h): `struct RTC_ALIGN(A)
/// RTCRayW` and `RTCHitW` (structures of arrays; see [`RTCHit`] for the Embree 4
/// trailing field), `RTCRayHitW` (aligned through its members, as `rtcIntersectW(3)`
/// requires of the packet) and the `valid` argument: one `int` per lane, `-1` active and
/// `0` inactive. The man pages only state the packet's alignment; the mask is read with
/// W-wide loads, so it gets the packet's alignment too.
macro_rules! packet_types {
    ($w:literal, $align:literal, $ray:ident, $hit:ident, $rayhit:ident, $valid:ident) => {
        #[repr(C, align($align))]
        #[derive(Clone, Copy, Debug, Default)]
        pub struct $ray {
            pub org_x: [f32; $w],
            pub org_y: [f32; $w],
            pub org_z: [f32; $w],
            pub tnear: [f32; $w],
            pub dir_x: [f32; $w],
            pub dir_y: [f32; $w],
            pub dir_z: [f32; $w],
            pub time: [f32; $w],
            pub tfar: [f32; $w],
            pub mask: [u32; $w],
            pub id: [u32; $w],
            pub flags: [u32; $w],
        }

        #[repr(C, align($align))]
        #[derive(Clone, Copy, Debug)]
        pub struct $hit {
            pub Ng_x: [f32; $w],
            pub Ng_y: [f32; $w],
            pub Ng_z: [f32; $w],
            pub u: [f32; $w],
            pub v: [f32; $w],
            pub primID: [u32; $w],
            pub geomID: [u32; $w],
            pub instID: [[u32; $w]; 1],
            #[cfg(heron_embree4)]
            pub instPrimID: [[u32; $w]; 1],
        }

        impl $hit {
            /// All lanes as `rtcIntersectW(3)` requires them: geometry and instance IDs
            /// invalid.
            pub const fn invalid() -> $hit {
                $hit {
                    Ng_x: [0.0; $w],
                    Ng_y: [0.0; $w],
                    Ng_z: [0.0; $w],
                    u: [0.0; $w],
                    v: [0.0; $w],
                    primID: [RTC_INVALID_GEOMETRY_ID; $w],
                    geomID: [RTC_INVALID_GEOMETRY_ID; $w],
                    instID: [[RTC_INVALID_GEOMETRY_ID; $w]],
                    #[cfg(heron_embree4)]
                    instPrimID: [[RTC_INVALID_GEOMETRY_ID; $w]],
                }
            }
        }

        #[repr(C)]
        #[derive(Clone, Copy, Debug)]
        pub struct $rayhit {
            pub ray: $ray,
            pub hit: $hit,
        }

        #[repr(C, align($align))]
        #[derive(Clone, Copy, Debug, Default)]
        pub struct $valid(pub [i32; $w]);
    };
}

packet_types!(4, 16, RTCRay4, RTCHit4, RTCRayHit4, ValidMask4);
packet_types!(8, 32, RTCRay8, RTCHit8, RTCRayHit8, ValidMask8);
packet_types!(16, 64, RTCRay16, RTCHit16, RTCRayHit16, ValidMask16);

// ---------------------------------------------------------------------------------------
// Layout checks. The expected numbers were printed by a throw-away C program compiled
// against /usr/include/embree3 (gcc, x86_64; `sizeof`, `_Alignof`, `offsetof`):
//   RTCRay 48/16 (tnear 12, dir_x 16, time 28, tfar 32, mask 36, id 40, flags 44)
//   RTCHit 32/16 (u 12, v 16, primID 20, geomID 24, instID 28)   RTCRayHit 80, hit at 48
//   RTCRay8 384/32 (tnear 96, dir_x 128, tfar 256, mask 288, flags 352)
//   RTCHit8 256/32 (u 96, primID 160, geomID 192, instID 224)    RTCRayHit8 640, hit 384
//   RTCIntersectContext 24/8 (filter 8, instID 16)               RTCBounds 32/16
// The Embree 4 numbers follow from its header (instPrimID appended after instID).

const _: () = {
    use std::mem::{align_of, offset_of, size_of};
    assert!(size_of::<RTCRay>() == 48 && align_of::<RTCRay>() == 16);
    assert!(offset_of!(RTCRay, tnear) == 12);
    assert!(offset_of!(RTCRay, dir_x) == 16);
    assert!(offset_of!(RTCRay, time) == 28);
    assert!(offset_of!(RTCRay, tfar) == 32);
    assert!(offset_of!(RTCRay, mask) == 36);
    assert!(offset_of!(RTCRay, id) == 40);
    assert!(offset_of!(RTCRay, flags) == 44);

    assert!(offset_of!(RTCHit, u) == 12);
    assert!(offset_of!(RTCHit, v) == 16);
    assert!(offset_of!(RTCHit, primID) == 20);
    assert!(offset_of!(RTCHit, geomID) == 24);
    assert!(offset_of!(RTCHit, instID) == 28);
    assert!(align_of::<RTCHit>() == 16);
    assert!(offset_of!(RTCRayHit, hit) == 48);
    assert!(align_of::<RTCRayHit>() == 16);

    assert!(size_of::<RTCRay8>() == 384 && align_of::<RTCRay8>() == 32);
    assert!(offset_of!(RTCRay8, tnear) == 96);
    assert!(offset_of!(RTCRay8, dir_x) == 128);
    assert!(offset_of!(RTCRay8, time) == 224);
    assert!(offset_of!(RTCRay8, tfar) == 256);
    assert!(offset_of!(RTCRay8, mask) == 288);
    assert!(offset_of!(RTCRay8, id) == 320);
    assert!(offset_of!(RTCRay8, flags) == 352);

    assert!(offset_of!(RTCHit8, u) == 96);
    assert!(offset_of!(RTCHit8, v) == 128);
    assert!(offset_of!(RTCHit8, primID) == 160);
    assert!(offset_of!(RTCHit8, geomID) == 192);
    assert!(offset_of!(RTCHit8, instID) == 224);
    assert!(align_of::<RTCHit8>() == 32);
    assert!(offset_of!(RTCRayHit8, hit) == 384);
    assert!(align_of::<RTCRayHit8>() == 32);

    assert!(size_of::<RTCBounds>() == 32 && align_of::<RTCBounds>() == 16);
    assert!(offset_of!(RTCBounds, upper_x) == 16);
    assert!(size_of::<ValidMask8>() == 32 && align_of::<ValidMask8>() == 32);

    // The other widths follow the same pattern: W lanes per field, aligned to 4W bytes.
    assert!(size_of::<RTCRay4>() == 192 && align_of::<RTCRay4>() == 16);
    assert!(offset_of!(RTCRayHit4, hit) == 192);
    assert!(size_of::<RTCRay16>() == 768 && align_of::<RTCRay16>() == 64);
    assert!(offset_of!(RTCRayHit16, hit) == 768);
    assert!(offset_of!(RTCHit16, instID) == 448);

    #[cfg(not(heron_embree4))]
    {
        assert!(size_of::<RTCHit>() == 32);
        assert!(size_of::<RTCRayHit>() == 80);
        assert!(size_of::<RTCHit8>() == 256);
        assert!(size_of::<RTCRayHit8>() == 640);
        assert!(size_of::<RTCHit4>() == 128 && size_of::<RTCHit16>() == 512);
        assert!(size_of::<RTCIntersectContext>() == 24);
        assert!(align_of::<RTCIntersectContext>() == 8);
        assert!(offset_of!(RTCIntersectContext, filter) == 8);
        assert!(offset_of!(RTCIntersectContext, instID) == 16);
    }
    #[cfg(heron_embree4)]
    {
        assert!(size_of::<RTCHit>() == 48);
        assert!(size_of::<RTCRayHit>() == 96);
        assert!(size_of::<RTCHit8>() == 288);
        assert!(size_of::<RTCRayHit8>() == 672);
        assert!(size_of::<RTCHit4>() == 144 && size_of::<RTCHit16>() == 576);
    }
};

// ---------------------------------------------------------------------------------------
// Functions common to Embree 3 and 4.

extern "C" {
    /// `rtcNewDevice(3)`: NULL on failure (query with `rtcGetDeviceError(NULL)`).
    pub fn rtcNewDevice(config: *const c_char) -> RTCDevice;
    /// `rtcReleaseDevice(3)`.
    pub fn rtcReleaseDevice(device: RTCDevice);
    /// `rtcGetDeviceProperty(3)`.
    pub fn rtcGetDeviceProperty(device: RTCDevice, prop: RTCDeviceProperty) -> isize;
    /// `rtcGetDeviceError(3)`: per thread and device; reads and clears the first error.
    pub fn rtcGetDeviceError(device: RTCDevice) -> RTCError;
    /// `rtcSetDeviceErrorFunction(3)`.
    pub fn rtcSetDeviceErrorFunction(
        device: RTCDevice,
        error: RTCErrorFunction,
        user_ptr: *mut c_void,
    );

    /// `rtcNewScene(3)`: NULL on failure.
    pub fn rtcNewScene(device: RTCDevice) -> RTCScene;
    /// `rtcReleaseScene(3)`.
    pub fn rtcReleaseScene(scene: RTCScene);
    /// `rtcSetSceneFlags(3)`.
    pub fn rtcSetSceneFlags(scene: RTCScene, flags: RTCSceneFlags);
    /// `rtcSetSceneBuildQuality(3)`.
    pub fn rtcSetSceneBuildQuality(scene: RTCScene, quality: RTCBuildQuality);
    /// `rtcAttachGeometry(3)`: IDs are sequential from 0 while nothing is detached.
    pub fn rtcAttachGeometry(scene: RTCScene, geometry: RTCGeometry) -> u32;
    /// `rtcCommitScene(3)`.
    pub fn rtcCommitScene(scene: RTCScene);
    /// `rtcGetSceneBounds(3)`: only after commit; `bounds_o` 16-byte aligned.
    pub fn rtcGetSceneBounds(scene: RTCScene, bounds_o: *mut RTCBounds);

    /// `rtcNewGeometry(3)`: NULL on failure.
    pub fn rtcNewGeometry(device: RTCDevice, kind: RTCGeometryType) -> RTCGeometry;
    /// `rtcReleaseGeometry(3)`.
    pub fn rtcReleaseGeometry(geometry: RTCGeometry);
    /// `rtcCommitGeometry(3)`.
    pub fn rtcCommitGeometry(geometry: RTCGeometry);
    /// `rtcSetNewGeometryBuffer(3)`: Embree-owned buffer, over-allocated for vertex
    /// buffers so the last element can be read with a 16-byte load; NULL on failure.
    pub fn rtcSetNewGeometryBuffer(
        geometry: RTCGeometry,
        kind: RTCBufferType,
        slot: u32,
        format: RTCFormat,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
}

// ---------------------------------------------------------------------------------------
// Ray queries: the one place where Embree 3 and 4 differ.

#[cfg(not(heron_embree4))]
pub use embree3_queries::*;
#[cfg(heron_embree4)]
pub use embree4_queries::*;

#[cfg(not(heron_embree4))]
mod embree3_queries {
    use super::*;

    /// `enum RTCIntersectContextFlags` (rtcore_common.h).
    pub type RTCIntersectContextFlags = u32;
    pub const RTC_INTERSECT_CONTEXT_FLAG_NONE: RTCIntersectContextFlags = 0;
    pub const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: RTCIntersectContextFlags = 0;
    pub const RTC_INTERSECT_CONTEXT_FLAG_COHERENT: RTCIntersectContextFlags = 1;

    /// `RTCFilterFunctionN`; heron never installs one, so its argument type is opaque.
    pub type RTCFilterFunctionN = Option<unsafe extern "C" fn(args: *const c_void)>;

    /// `struct RTCIntersectContext` (rtcore_common.h) with `RTC_MAX_INSTANCE_LEVEL_COUNT
    /// == 1` (no `instStackSize`) and `RTC_MIN_WIDTH == 0` (no `minWidthDistanceFactor`).
    #[repr(C)]
    #[derive(Clone, Copy, Debug)]
    pub struct RTCIntersectContext {
        pub flags: RTCIntersectContextFlags,
        pub filter: RTCFilterFunctionN,
        pub instID: [u32; 1],
    }

    /// `rtcInitIntersectContext(3)`, an inline function in the header, replicated: flags
    /// INCOHERENT, no filter, instance stack all `RTC_INVALID_GEOMETRY_ID`.
    pub const fn rtc_init_intersect_context() -> RTCIntersectContext {
        RTCIntersectContext {
            flags: RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
            filter: None,
            instID: [RTC_INVALID_GEOMETRY_ID],
        }
    }

    extern "C" {
        /// `rtcIntersect1(3)`: no error checks; `rayhit` 16-byte aligned.
        pub fn rtcIntersect1(
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit,
        );
        /// `rtcOccluded1(3)`: sets `tfar = -inf` on a hit.
        pub fn rtcOccluded1(scene: RTCScene, context: *mut RTCIntersectContext, ray: *mut RTCRay);
        /// `rtcIntersect8(3)`: packet 32-byte aligned; `valid` -1 active / 0 inactive.
        pub fn rtcIntersect8(
            valid: *const i32,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit8,
        );
        /// `rtcOccluded8(3)`.
        pub fn rtcOccluded8(
            valid: *const i32,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            ray: *mut RTCRay8,
        );
        /// `rtcIntersect4(3)`: packet 16-byte aligned.
        pub fn rtcIntersect4(
            valid: *const i32,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit4,
        );
        /// `rtcOccluded4(3)`.
        pub fn rtcOccluded4(
            valid: *const i32,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            ray: *mut RTCRay4,
        );
        /// `rtcOccluded16(3)`.
        pub fn rtcOccluded16(
            valid: *const i32,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            ray: *mut RTCRay16,
        );
        /// `rtcIntersect16(3)`: packet 64-byte aligned.
        pub fn rtcIntersect16(
            valid: *const i32,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit16,
        );
        /// `rtcIntersect1M(3)`: a stream of M single-ray records `byteStride` apart.
        pub fn rtcIntersect1M(
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit,
            M: u32,
            byteStride: usize,
        );
    }

    /// Closest hits of a 4-ray packet.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn intersect4(
        valid: &ValidMask4,
        scene: RTCScene,
        rayhit: &mut RTCRayHit4,
        coherent: bool,
    ) {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect1`; the packet and the mask are align(16).
        unsafe { rtcIntersect4(valid.0.as_ptr(), scene, &mut ctx, rayhit) }
    }

    /// Closest hits of a 16-ray packet.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn intersect16(
        valid: &ValidMask16,
        scene: RTCScene,
        rayhit: &mut RTCRayHit16,
        coherent: bool,
    ) {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect1`; the packet and the mask are align(64).
        unsafe { rtcIntersect16(valid.0.as_ptr(), scene, &mut ctx, rayhit) }
    }

    /// Whether the library has the stream API (`rtcIntersect1M`): Embree 3 does.
    pub const STREAM_API: bool = true;

    /// Closest hits of a stream of single rays (Embree 3's stream API); returns true.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn intersect1m(scene: RTCScene, rayhits: &mut [RTCRayHit], coherent: bool) -> bool {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect1`; the records are contiguous, each align(16), and M
        // fits in u32 (the callers pass chunks of at most a few thousand).
        unsafe {
            rtcIntersect1M(
                scene,
                &mut ctx,
                rayhits.as_mut_ptr(),
                rayhits.len() as u32,
                std::mem::size_of::<RTCRayHit>(),
            )
        };
        true
    }

    /// `rtcInitIntersectContext` with the coherence flag, without a branch (it is made
    /// for every query).
    #[inline(always)]
    fn context(coherent: bool) -> RTCIntersectContext {
        RTCIntersectContext {
            flags: coherent as u32 * RTC_INTERSECT_CONTEXT_FLAG_COHERENT,
            ..rtc_init_intersect_context()
        }
    }

    /// Closest hit of one ray.
    ///
    /// # Safety
    /// `scene` is a live, committed scene not being modified concurrently.
    pub unsafe fn intersect1(scene: RTCScene, rayhit: &mut RTCRayHit, coherent: bool) {
        let mut ctx = context(coherent);
        // SAFETY: the caller guarantees `scene`; `ctx` and `rayhit` are valid, exclusive
        // and aligned (RTCRayHit is align(16)) for the duration of the call.
        unsafe { rtcIntersect1(scene, &mut ctx, rayhit) }
    }

    /// Occlusion of one ray.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded1(scene: RTCScene, ray: &mut RTCRay, coherent: bool) {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect1`; RTCRay is align(16).
        unsafe { rtcOccluded1(scene, &mut ctx, ray) }
    }

    /// Closest hits of an 8-ray packet.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn intersect8(
        valid: &ValidMask8,
        scene: RTCScene,
        rayhit: &mut RTCRayHit8,
        coherent: bool,
    ) {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect1`; the packet and the mask are align(32).
        unsafe { rtcIntersect8(valid.0.as_ptr(), scene, &mut ctx, rayhit) }
    }

    /// Occlusion of an 8-ray packet.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded8(
        valid: &ValidMask8,
        scene: RTCScene,
        ray: &mut RTCRay8,
        coherent: bool,
    ) {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect8`.
        unsafe { rtcOccluded8(valid.0.as_ptr(), scene, &mut ctx, ray) }
    }

    /// Occlusion of a 4-ray packet.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded4(
        valid: &ValidMask4,
        scene: RTCScene,
        ray: &mut RTCRay4,
        coherent: bool,
    ) {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect4`.
        unsafe { rtcOccluded4(valid.0.as_ptr(), scene, &mut ctx, ray) }
    }

    /// Occlusion of a 16-ray packet.
    ///
    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded16(
        valid: &ValidMask16,
        scene: RTCScene,
        ray: &mut RTCRay16,
        coherent: bool,
    ) {
        let mut ctx = context(coherent);
        // SAFETY: as in `intersect16`.
        unsafe { rtcOccluded16(valid.0.as_ptr(), scene, &mut ctx, ray) }
    }
}

/// Embree 4 (tested with 4.4): `rtcIntersect1(scene, rayhit, args)` etc., with
/// `args = NULL` meaning the defaults of `rtcInitIntersectArguments(3)` (incoherent, all
/// features). Adding the coherence hint means declaring `RTCIntersectArguments` and
/// `RTCOccludedArguments` here; nothing outside this file changes.
#[cfg(heron_embree4)]
mod embree4_queries {
    use super::*;

    extern "C" {
        pub fn rtcIntersect1(scene: RTCScene, rayhit: *mut RTCRayHit, args: *mut c_void);
        pub fn rtcOccluded1(scene: RTCScene, ray: *mut RTCRay, args: *mut c_void);
        pub fn rtcIntersect8(
            valid: *const i32,
            scene: RTCScene,
            rayhit: *mut RTCRayHit8,
            args: *mut c_void,
        );
        pub fn rtcOccluded8(
            valid: *const i32,
            scene: RTCScene,
            ray: *mut RTCRay8,
            args: *mut c_void,
        );
        pub fn rtcIntersect4(
            valid: *const i32,
            scene: RTCScene,
            rayhit: *mut RTCRayHit4,
            args: *mut c_void,
        );
        pub fn rtcIntersect16(
            valid: *const i32,
            scene: RTCScene,
            rayhit: *mut RTCRayHit16,
            args: *mut c_void,
        );
        pub fn rtcOccluded4(
            valid: *const i32,
            scene: RTCScene,
            ray: *mut RTCRay4,
            args: *mut c_void,
        );
        pub fn rtcOccluded16(
            valid: *const i32,
            scene: RTCScene,
            ray: *mut RTCRay16,
            args: *mut c_void,
        );
    }

    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn intersect4(
        valid: &ValidMask4,
        scene: RTCScene,
        rayhit: &mut RTCRayHit4,
        _coherent: bool,
    ) {
        // SAFETY: as in `intersect1`; the packet and the mask are align(16).
        unsafe { rtcIntersect4(valid.0.as_ptr(), scene, rayhit, std::ptr::null_mut()) }
    }

    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn intersect16(
        valid: &ValidMask16,
        scene: RTCScene,
        rayhit: &mut RTCRayHit16,
        _coherent: bool,
    ) {
        // SAFETY: as in `intersect1`; the packet and the mask are align(64).
        unsafe { rtcIntersect16(valid.0.as_ptr(), scene, rayhit, std::ptr::null_mut()) }
    }

    /// Whether the library has the stream API: Embree 4 removed it.
    pub const STREAM_API: bool = false;

    /// Embree 4 removed the stream API (`rtcIntersect1M` and friends): returns false and
    /// leaves the records untouched.
    ///
    /// # Safety
    /// Always safe; `unsafe` only to match the Embree 3 signature.
    pub unsafe fn intersect1m(
        _scene: RTCScene,
        _rayhits: &mut [RTCRayHit],
        _coherent: bool,
    ) -> bool {
        false
    }

    /// # Safety
    /// `scene` is a live, committed scene not being modified concurrently.
    pub unsafe fn intersect1(scene: RTCScene, rayhit: &mut RTCRayHit, _coherent: bool) {
        // SAFETY: the caller guarantees `scene`; `rayhit` is valid and aligned; NULL args
        // are allowed.
        unsafe { rtcIntersect1(scene, rayhit, std::ptr::null_mut()) }
    }

    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded1(scene: RTCScene, ray: &mut RTCRay, _coherent: bool) {
        // SAFETY: as in `intersect1`.
        unsafe { rtcOccluded1(scene, ray, std::ptr::null_mut()) }
    }

    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn intersect8(
        valid: &ValidMask8,
        scene: RTCScene,
        rayhit: &mut RTCRayHit8,
        _coherent: bool,
    ) {
        // SAFETY: as in `intersect1`; the packet and the mask are align(32).
        unsafe { rtcIntersect8(valid.0.as_ptr(), scene, rayhit, std::ptr::null_mut()) }
    }

    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded8(
        valid: &ValidMask8,
        scene: RTCScene,
        ray: &mut RTCRay8,
        _coherent: bool,
    ) {
        // SAFETY: as in `intersect8`.
        unsafe { rtcOccluded8(valid.0.as_ptr(), scene, ray, std::ptr::null_mut()) }
    }

    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded4(
        valid: &ValidMask4,
        scene: RTCScene,
        ray: &mut RTCRay4,
        _coherent: bool,
    ) {
        // SAFETY: as in `intersect4`.
        unsafe { rtcOccluded4(valid.0.as_ptr(), scene, ray, std::ptr::null_mut()) }
    }

    /// # Safety
    /// As [`intersect1`].
    pub unsafe fn occluded16(
        valid: &ValidMask16,
        scene: RTCScene,
        ray: &mut RTCRay16,
        _coherent: bool,
    ) {
        // SAFETY: as in `intersect16`.
        unsafe { rtcOccluded16(valid.0.as_ptr(), scene, ray, std::ptr::null_mut()) }
    }
}
