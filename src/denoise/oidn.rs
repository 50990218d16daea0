//! Open Image Denoise, loaded when first used.
//!
//! The library is opened with `dlopen` (the `libloading` crate) rather
//! than linked: a linked library missing at run time stops the program
//! before `main` with the system loader's message, while a library opened
//! here that is missing, or of another major version, is a
//! [`DenoiseError`] naming each file tried. Only the functions of OIDN 2's
//! C API that lumen calls are declared.
//!
//! Where it is looked for: with `OIDN_DIR` set, `$OIDN_DIR/lib/` (the
//! layout of OIDN's release archives and of the `pyoidn` wheel's
//! `pyoidn/oidn`), then `$OIDN_DIR` itself; otherwise the system's search
//! (`LD_LIBRARY_PATH`, then the linker cache).

use super::{DenoiseError, Inputs, Quality};
use crate::math::Color;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

type Device = *mut c_void;
type Filter = *mut c_void;

/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_CPU: c_int = 1;
/// `OIDN_QUALITY_FAST`, `_BALANCED` and `_HIGH`.
fn quality(q: Quality) -> c_int {
    match q {
        Quality::Fast => 4,
        Quality::Balanced => 5,
        Quality::High => 6,
    }
}
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;
/// The major version whose API is declared here.
const MAJOR: c_int = 2;

/// The library's file name, as its major version installs it.
#[cfg(target_os = "macos")]
pub const FILE_NAME: &str = "libOpenImageDenoise.2.dylib";
/// The library's file name, as its major version installs it.
#[cfg(target_os = "windows")]
pub const FILE_NAME: &str = "OpenImageDenoise.dll";
/// The library's file name, as its major version installs it.
#[cfg(not(any(target_os = "macos", target_os = "windows")))]
pub const FILE_NAME: &str = "libOpenImageDenoise.so.2";

/// The loaded library and the functions lumen calls.
pub struct Library {
    path: PathBuf,
    version: c_int,
    new_device: unsafe extern "C" fn(c_int) -> Device,
    set_device_int: unsafe extern "C" fn(Device, *const c_char, c_int),
    set_device_bool: unsafe extern "C" fn(Device, *const c_char, bool),
    get_device_int: unsafe extern "C" fn(Device, *const c_char) -> c_int,
    commit_device: unsafe extern "C" fn(Device),
    device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> c_int,
    release_device: unsafe extern "C" fn(Device),
    new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    #[allow(clippy::type_complexity)]
    set_image: unsafe extern "C" fn(
        Filter,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_filter_bool: unsafe extern "C" fn(Filter, *const c_char, bool),
    set_filter_int: unsafe extern "C" fn(Filter, *const c_char, c_int),
    commit_filter: unsafe extern "C" fn(Filter),
    execute_filter: unsafe extern "C" fn(Filter),
    release_filter: unsafe extern "C" fn(Filter),
    // Kept open for the functions above, which point into it.
    _library: libloading::Library,
}

impl Library {
    /// The library, loaded on the first call.
    pub fn get() -> Result<&'static Library, DenoiseError> {
        static LIBRARY: OnceLock<Result<Library, DenoiseError>> = OnceLock::new();
        LIBRARY
            .get_or_init(|| Library::open(std::env::var_os("OIDN_DIR").map(PathBuf::from)))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Its file and version, for messages.
    pub fn describe(&self) -> String {
        format!(
            "Open Image Denoise {}.{}.{} ({})",
            self.version / 10000,
            self.version / 100 % 100,
            self.version % 100,
            self.path.display()
        )
    }

    /// The files to try, in order (see the module's documentation).
    fn candidates(dir: Option<&Path>) -> Vec<PathBuf> {
        match dir {
            Some(dir) => vec![dir.join("lib").join(FILE_NAME), dir.join(FILE_NAME)],
            None => vec![PathBuf::from(FILE_NAME)],
        }
    }

    /// Opens the library in `dir` (laid out as `OIDN_DIR` is, see the
    /// module's documentation), or the system's when `None`. [`Library::get`]
    /// opens the one `OIDN_DIR` names, once.
    pub fn open(dir: Option<PathBuf>) -> Result<Library, DenoiseError> {
        let mut tried = Vec::new();
        for path in Self::candidates(dir.as_deref()) {
            if dir.is_some() && !path.exists() {
                tried.push((path, "no such file".to_string()));
                continue;
            }
            // SAFETY: loading runs the library's initialisers; OIDN's only
            // set up its own state.
            match unsafe { libloading::Library::new(&path) } {
                Ok(library) => return Self::bind(library, path),
                Err(e) => tried.push((path, e.to_string())),
            }
        }
        Err(DenoiseError::NotFound { tried })
    }

    fn bind(library: libloading::Library, path: PathBuf) -> Result<Library, DenoiseError> {
        macro_rules! symbol {
            ($name:literal) => {
                // SAFETY: the type is the function's in OIDN 2's C API
                // (oidn.h); the pointer lives as long as `library`, which
                // the returned value owns.
                match unsafe { library.get($name) } {
                    Ok(f) => *f,
                    Err(_) => {
                        return Err(DenoiseError::Incompatible {
                            path,
                            message: format!(
                                "has no function {}: not Open Image Denoise {MAJOR}",
                                $name
                            ),
                        })
                    }
                }
            };
        }
        let mut lib = Library {
            version: 0,
            new_device: symbol!("oidnNewDevice"),
            set_device_int: symbol!("oidnSetDeviceInt"),
            set_device_bool: symbol!("oidnSetDeviceBool"),
            get_device_int: symbol!("oidnGetDeviceInt"),
            commit_device: symbol!("oidnCommitDevice"),
            device_error: symbol!("oidnGetDeviceError"),
            release_device: symbol!("oidnReleaseDevice"),
            new_filter: symbol!("oidnNewFilter"),
            set_image: symbol!("oidnSetSharedFilterImage"),
            set_filter_bool: symbol!("oidnSetFilterBool"),
            set_filter_int: symbol!("oidnSetFilterInt"),
            commit_filter: symbol!("oidnCommitFilter"),
            execute_filter: symbol!("oidnExecuteFilter"),
            release_filter: symbol!("oidnReleaseFilter"),
            path,
            _library: library,
        };
        let version = lib.device(1)?.int("version");
        lib.version = version;
        if lib.version / 10000 != MAJOR {
            return Err(DenoiseError::Incompatible {
                path: lib.path.clone(),
                message: format!(
                    "is Open Image Denoise version {}, and lumen needs version {MAJOR}",
                    lib.version / 10000
                ),
            });
        }
        Ok(lib)
    }

    /// A committed CPU device running `threads` threads, not pinned to
    /// cores (which would fight the render's own threads).
    fn device(&self, threads: usize) -> Result<DeviceHandle<'_>, DenoiseError> {
        // SAFETY: a null device is OIDN's documented "no device" value
        // for its error query.
        let raw = unsafe { (self.new_device)(DEVICE_CPU) };
        if raw.is_null() {
            return Err(self
                .error(std::ptr::null_mut())
                .unwrap_or_else(|| DenoiseError::Oidn("no CPU device could be created".into())));
        }
        let device = DeviceHandle { lib: self, raw };
        let threads = c_int::try_from(threads.max(1)).unwrap_or(c_int::MAX);
        // SAFETY: `raw` is a live device; the names are NUL-terminated.
        unsafe {
            (self.set_device_int)(raw, c"numThreads".as_ptr(), threads);
            (self.set_device_bool)(raw, c"setAffinity".as_ptr(), false);
            (self.commit_device)(raw);
        }
        device.check()?;
        Ok(device)
    }

    /// The error pending on `device` (null: the library's own), if any.
    fn error(&self, device: Device) -> Option<DenoiseError> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: `device` is live or null; OIDN sets `message` to a
        // NUL-terminated string valid until its next call, or to null.
        let code = unsafe { (self.device_error)(device, &mut message) };
        (code != 0).then(|| {
            let text = if message.is_null() {
                format!("error {code}")
            } else {
                // SAFETY: see above.
                unsafe { CStr::from_ptr(message) }
                    .to_string_lossy()
                    .into_owned()
            };
            DenoiseError::Oidn(text)
        })
    }

    /// See [`super::denoise`].
    pub(super) fn denoise(
        &self,
        inputs: &Inputs,
        threads: usize,
    ) -> Result<Vec<Color>, DenoiseError> {
        let device = self.device(threads)?;
        let (w, h) = (inputs.width, inputs.height);
        let flat = |v: &[Color]| -> Vec<f32> { v.iter().flat_map(|c| [c.x, c.y, c.z]).collect() };
        let mut color = flat(inputs.color);
        let mut albedo = inputs.albedo.map(flat);
        let mut normal = inputs.normal.map(flat);
        // Prefiltered auxiliary images: each cleaned by a filter of its own
        // (written in place), so that the image's filter can trust them.
        let prefilter = |name: &CStr, buffer: &mut Vec<f32>, q: Quality| {
            let mut clean = vec![0.0; buffer.len()];
            let filter = device.filter()?;
            filter.image(name, buffer, w, h);
            filter.image(c"output", &mut clean, w, h);
            filter.int(c"quality", quality(q));
            filter.run()?;
            *buffer = clean;
            Ok::<_, DenoiseError>(())
        };
        if let Some(q) = inputs.options.prefilter {
            if let Some(albedo) = albedo.as_mut() {
                prefilter(c"albedo", albedo, q)?;
            }
            if let Some(normal) = normal.as_mut() {
                prefilter(c"normal", normal, q)?;
            }
        }
        let mut output = vec![0.0; color.len()];
        let filter = device.filter()?;
        filter.image(c"color", &mut color, w, h);
        if let Some(albedo) = albedo.as_mut() {
            filter.image(c"albedo", albedo, w, h);
        }
        if let Some(normal) = normal.as_mut() {
            filter.image(c"normal", normal, w, h);
        }
        filter.image(c"output", &mut output, w, h);
        filter.flag(c"hdr", true);
        filter.flag(
            c"cleanAux",
            albedo.is_some() && inputs.options.prefilter.is_some(),
        );
        filter.int(c"quality", quality(inputs.options.quality));
        filter.run()?;
        Ok(output
            .chunks_exact(3)
            .map(|p| Color::new(p[0], p[1], p[2]))
            .collect())
    }
}

/// A device, released when dropped.
struct DeviceHandle<'a> {
    lib: &'a Library,
    raw: Device,
}

impl DeviceHandle<'_> {
    fn check(&self) -> Result<(), DenoiseError> {
        self.lib.error(self.raw).map_or(Ok(()), Err)
    }

    fn int(&self, name: &str) -> c_int {
        let name = CString::new(name).expect("parameter names have no NUL");
        // SAFETY: `raw` is a live device; `name` is NUL-terminated.
        unsafe { (self.lib.get_device_int)(self.raw, name.as_ptr()) }
    }

    /// A new `RT` filter of this device.
    fn filter(&self) -> Result<FilterHandle<'_>, DenoiseError> {
        // SAFETY: `raw` is a live device; the name is NUL-terminated.
        let raw = unsafe { (self.lib.new_filter)(self.raw, c"RT".as_ptr()) };
        self.check()?;
        if raw.is_null() {
            return Err(DenoiseError::Oidn("no RT filter could be created".into()));
        }
        Ok(FilterHandle { device: self, raw })
    }
}

impl Drop for DeviceHandle<'_> {
    fn drop(&mut self) {
        // SAFETY: `raw` is live and released once, here; its filters
        // (which borrow this handle) are gone.
        unsafe { (self.lib.release_device)(self.raw) }
    }
}

/// A filter, released when dropped. The images it is given are borrowed
/// until it is: see [`FilterHandle::image`].
struct FilterHandle<'a> {
    device: &'a DeviceHandle<'a>,
    raw: Filter,
}

impl FilterHandle<'_> {
    /// Shares `pixels` (RGB triples, `w`×`h`, row-major) as the image
    /// `name`.
    fn image(&self, name: &CStr, pixels: &mut [f32], w: usize, h: usize) {
        assert_eq!(pixels.len(), w * h * 3, "an image of the filter's size");
        // SAFETY: `raw` is a live filter; the buffer holds w·h packed
        // float triples (checked above), and outlives the filter's run,
        // which happens in the same `denoise` call that owns both.
        unsafe {
            (self.device.lib.set_image)(
                self.raw,
                name.as_ptr(),
                pixels.as_mut_ptr().cast(),
                FORMAT_FLOAT3,
                w,
                h,
                0,
                0,
                0,
            )
        }
    }

    fn int(&self, name: &CStr, value: c_int) {
        // SAFETY: `raw` is a live filter; the name is NUL-terminated.
        unsafe { (self.device.lib.set_filter_int)(self.raw, name.as_ptr(), value) }
    }

    fn flag(&self, name: &CStr, value: bool) {
        // SAFETY: `raw` is a live filter; the name is NUL-terminated.
        unsafe { (self.device.lib.set_filter_bool)(self.raw, name.as_ptr(), value) }
    }

    /// Commits and executes the filter (synchronously on the CPU device).
    fn run(&self) -> Result<(), DenoiseError> {
        // SAFETY: `raw` is a live filter whose images are set and alive.
        unsafe {
            (self.device.lib.commit_filter)(self.raw);
        }
        self.device.check()?;
        // SAFETY: as above; committing succeeded.
        unsafe {
            (self.device.lib.execute_filter)(self.raw);
        }
        self.device.check()
    }
}

impl Drop for FilterHandle<'_> {
    fn drop(&mut self) {
        // SAFETY: `raw` is live and released once, here.
        unsafe { (self.device.lib.release_filter)(self.raw) }
    }
}
