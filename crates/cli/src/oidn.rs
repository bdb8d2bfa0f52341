//! Intel Open Image Denoise (OIDN), loaded when a denoise is asked for:
//! a run-time dependency, never a build-time one, so that the default
//! build works on machines without it.
//!
//! The library is looked for, in order, in `OIDN_DIR` (a folder holding
//! `libOpenImageDenoise.so.2`, or its `lib/` subfolder), on the system's
//! library path, and in the folder of PyPI's `pyoidn` wheel, which bundles
//! OIDN 2 with its CPU device (`pip install pyoidn`; Debian 12 has no OIDN
//! package). Only the dozen C functions of OIDN's documented workflow are
//! declared: a CPU device, the generic ray-tracing filter `"RT"` on HDR
//! colour, and the auxiliary albedo and normal images prefiltered first
//! with the same filter (OIDN's "cleanAux" workflow, its recommended one
//! for final frames).

use libloading::Library;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};

type Device = *mut c_void;
type Filter = *mut c_void;

/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;
/// `OIDN_ERROR_NONE`.
const ERROR_NONE: c_int = 0;

/// The library's file names, newest ABI first.
const NAMES: [&str; 2] = ["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];

/// What to tell a user who has no OIDN.
pub const INSTALL_HINT: &str = "install it with `pip install pyoidn` (its wheel bundles the \
     library), or set OIDN_DIR to a folder holding libOpenImageDenoise.so.2";

/// OIDN's quality settings (`OIDN_QUALITY_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    Fast,
    Balanced,
    High,
}

impl Quality {
    /// From its name on the command line.
    pub fn parse(s: &str) -> Option<Quality> {
        match s {
            "fast" => Some(Quality::Fast),
            "balanced" => Some(Quality::Balanced),
            "high" => Some(Quality::High),
            _ => None,
        }
    }

    fn value(self) -> c_int {
        match self {
            Quality::Fast => 4,
            Quality::Balanced => 5,
            Quality::High => 6,
        }
    }
}

/// The images of one denoise, each `width × height` RGB triples, rows top
/// to bottom. A normal image needs an albedo image (OIDN's rule).
pub struct Inputs<'a> {
    pub width: usize,
    pub height: usize,
    pub color: &'a [f32],
    /// Prefiltered in place.
    pub albedo: Option<&'a mut [f32]>,
    /// Prefiltered in place.
    pub normal: Option<&'a mut [f32]>,
    pub quality: Quality,
    /// Whether the albedo and normal are prefiltered first and then
    /// passed as clean (`cleanAux`: OIDN's recommended final-frame
    /// workflow, three filter runs), or passed as they are (its mode for
    /// noisy auxiliary images, one run).
    pub prefilter: bool,
}

/// A loaded OIDN library and its functions.
pub struct Oidn {
    path: PathBuf,
    new_device: unsafe extern "C" fn(c_int) -> Device,
    commit_device: unsafe extern "C" fn(Device),
    release_device: unsafe extern "C" fn(Device),
    get_device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> c_int,
    new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    #[allow(clippy::type_complexity)]
    set_shared_filter_image: unsafe extern "C" fn(
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
    /// Kept loaded while the function pointers above are in use (dropped
    /// last: fields drop in order).
    _lib: Library,
}

/// Where to look for the library, in order: `(path, named)`, where
/// `named` means the user or a package named the file (a failure to load
/// it is then an error, not a reason to look further).
fn candidates() -> Vec<(PathBuf, bool)> {
    let mut c = Vec::new();
    if let Some(dir) = std::env::var_os("OIDN_DIR") {
        let dir = PathBuf::from(dir);
        for d in [dir.clone(), dir.join("lib")] {
            c.extend(NAMES.iter().map(|n| (d.join(n), true)));
        }
    }
    // Bare names: the dynamic loader's search path.
    c.extend(NAMES.iter().map(|n| (PathBuf::from(n), false)));
    if let Some(dir) = pyoidn_lib_dir() {
        c.extend(NAMES.iter().map(|n| (dir.join(n), true)));
    }
    c
}

/// The library folder of an installed `pyoidn` (found without importing
/// it, which would load the library into Python).
fn pyoidn_lib_dir() -> Option<PathBuf> {
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import importlib.util as u; s = u.find_spec('pyoidn'); print(s.origin if s and s.origin else '')",
        ])
        .stderr(std::process::Stdio::null())
        .output()
        .ok()?;
    let origin = String::from_utf8(out.stdout).ok()?;
    let origin = Path::new(origin.trim());
    Some(origin.parent()?.join("oidn").join("lib"))
}

impl Oidn {
    /// Loads the library from the first place that has it (see the module
    /// documentation).
    pub fn load() -> Result<Oidn, String> {
        Oidn::load_from(&candidates())
    }

    /// Loads the first of `candidates` that exists: a named file that does
    /// not load is an error naming it; a bare name that does not load is
    /// not on the library path.
    pub fn load_from(candidates: &[(PathBuf, bool)]) -> Result<Oidn, String> {
        for (path, named) in candidates {
            if *named && !path.exists() {
                continue;
            }
            match Oidn::open(path) {
                Ok(o) => return Ok(o),
                Err(e) if *named => return Err(e),
                Err(_) => continue,
            }
        }
        Err(format!(
            "Intel Open Image Denoise (libOpenImageDenoise.so.2) not found: {INSTALL_HINT}"
        ))
    }

    /// Opens the library at `path` and finds its functions.
    fn open(path: &Path) -> Result<Oidn, String> {
        // SAFETY: loading runs the library's initialisers; OIDN's are
        // those of a C++ shared library, safe to run on any thread.
        let lib = unsafe { Library::new(path) }
            .map_err(|e| format!("{}: cannot load Open Image Denoise: {e}", path.display()))?;
        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the symbol's type is the one `oidn.h` declares
                // for it (OIDN 1 and 2 alike), and the pointer is used
                // only while `lib` is loaded (it lives in the same struct).
                *unsafe { lib.get(concat!($name, "\0").as_bytes()) }.map_err(|e| {
                    format!(
                        "{}: not an Open Image Denoise library ({} missing: {e})",
                        path.display(),
                        $name
                    )
                })?
            };
        }
        Ok(Oidn {
            path: path.to_path_buf(),
            new_device: sym!("oidnNewDevice"),
            commit_device: sym!("oidnCommitDevice"),
            release_device: sym!("oidnReleaseDevice"),
            get_device_error: sym!("oidnGetDeviceError"),
            new_filter: sym!("oidnNewFilter"),
            set_shared_filter_image: sym!("oidnSetSharedFilterImage"),
            set_filter_bool: sym!("oidnSetFilterBool"),
            set_filter_int: sym!("oidnSetFilterInt"),
            commit_filter: sym!("oidnCommitFilter"),
            execute_filter: sym!("oidnExecuteFilter"),
            release_filter: sym!("oidnReleaseFilter"),
            _lib: lib,
        })
    }

    /// Denoises `inputs.color` (HDR), with the auxiliary images where
    /// given (prefiltered first, in place): the denoised RGB triples.
    pub fn denoise(&self, inputs: Inputs) -> Result<Vec<f32>, String> {
        let Inputs {
            width,
            height,
            color,
            albedo,
            normal,
            quality,
            prefilter,
        } = inputs;
        let n = width
            .checked_mul(height)
            .and_then(|p| p.checked_mul(3))
            .ok_or("image too large to denoise")?;
        let sizes_ok = color.len() == n
            && albedo.as_ref().is_none_or(|a| a.len() == n)
            && normal.as_ref().is_none_or(|a| a.len() == n);
        if !sizes_ok || n == 0 {
            return Err("denoise: the images' sizes disagree or are empty".into());
        }
        if normal.is_some() && albedo.is_none() {
            return Err("denoise: a normal image needs an albedo image too".into());
        }
        let device = DeviceGuard::new(self)?;
        // OIDN writes only "output"; the colour is copied so that the
        // shared image may be passed as mutable memory, as the C API takes
        // it.
        let mut color = color.to_vec();
        let mut output = vec![0.0f32; n];
        let clean = albedo.is_some() && prefilter;
        let mut albedo = albedo;
        let mut normal = normal;
        for (name, image) in [
            ("albedo", albedo.as_deref_mut()),
            ("normal", normal.as_deref_mut()),
        ] {
            if let Some(image) = image.filter(|_| prefilter) {
                let f = device.filter()?;
                f.image(name, image, width, height)?;
                f.image("output", image, width, height)?;
                f.set_int(c"quality", quality.value());
                f.run()?;
            }
        }
        let f = device.filter()?;
        f.image("color", &mut color, width, height)?;
        if let Some(a) = albedo {
            f.image("albedo", a, width, height)?;
        }
        if let Some(nrm) = normal {
            f.image("normal", nrm, width, height)?;
        }
        f.image("output", &mut output, width, height)?;
        f.set_bool(c"hdr", true);
        f.set_bool(c"cleanAux", clean);
        f.set_int(c"quality", quality.value());
        f.run()?;
        Ok(output)
    }
}

/// An OIDN CPU device, released when dropped.
struct DeviceGuard<'a> {
    oidn: &'a Oidn,
    device: Device,
}

impl<'a> DeviceGuard<'a> {
    fn new(oidn: &'a Oidn) -> Result<DeviceGuard<'a>, String> {
        // SAFETY: the functions come from the loaded library with their
        // declared types; a null device is checked before any use.
        let device = unsafe { (oidn.new_device)(DEVICE_TYPE_CPU) };
        if device.is_null() {
            return Err(format!(
                "{}: Open Image Denoise made no CPU device (its CPU module, \
                 libOpenImageDenoise_device_cpu, must sit beside it)",
                oidn.path.display()
            ));
        }
        let d = DeviceGuard { oidn, device };
        // SAFETY: a device just made.
        unsafe { (oidn.commit_device)(device) };
        d.check()?;
        Ok(d)
    }

    /// The device's pending error, if any.
    fn check(&self) -> Result<(), String> {
        let mut msg: *const c_char = std::ptr::null();
        // SAFETY: a live device; OIDN sets `msg` to a string it owns (or
        // leaves it null), valid until the next call on the device.
        let code = unsafe { (self.oidn.get_device_error)(self.device, &mut msg) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let text = if msg.is_null() {
            String::from("unknown error")
        } else {
            // SAFETY: a NUL-terminated string from OIDN (see above).
            unsafe { CStr::from_ptr(msg) }
                .to_string_lossy()
                .into_owned()
        };
        Err(format!("Open Image Denoise: {text} (error {code})"))
    }

    /// A new `"RT"` filter on the device.
    fn filter(&self) -> Result<FilterGuard<'_, 'a>, String> {
        // SAFETY: a live device and a NUL-terminated type name.
        let filter = unsafe { (self.oidn.new_filter)(self.device, c"RT".as_ptr()) };
        self.check()?;
        if filter.is_null() {
            return Err("Open Image Denoise made no \"RT\" filter".into());
        }
        Ok(FilterGuard {
            device: self,
            filter,
        })
    }
}

impl Drop for DeviceGuard<'_> {
    fn drop(&mut self) {
        // SAFETY: a device made by `new`, released once; its filters were
        // released first (each borrows this guard).
        unsafe { (self.oidn.release_device)(self.device) };
    }
}

/// A filter, released when dropped; the images it was given must outlive
/// its execution (they are borrowed by the calls that run it).
struct FilterGuard<'d, 'a> {
    device: &'d DeviceGuard<'a>,
    filter: Filter,
}

impl FilterGuard<'_, '_> {
    /// Sets image `name` to `data`, `width × height` RGB float triples.
    fn image(
        &self,
        name: &str,
        data: &mut [f32],
        width: usize,
        height: usize,
    ) -> Result<(), String> {
        debug_assert_eq!(data.len(), width * height * 3);
        let name = CString::new(name).map_err(|e| e.to_string())?;
        // SAFETY: `data` holds `width × height` packed float triples (the
        // strides 0 mean packed) and outlives the filter's execution,
        // which happens within the caller's borrow of it.
        unsafe {
            (self.device.oidn.set_shared_filter_image)(
                self.filter,
                name.as_ptr(),
                data.as_mut_ptr().cast(),
                FORMAT_FLOAT3,
                width,
                height,
                0,
                0,
                0,
            )
        };
        self.device.check()
    }

    fn set_bool(&self, name: &CStr, value: bool) {
        // SAFETY: a live filter and a NUL-terminated parameter name.
        unsafe { (self.device.oidn.set_filter_bool)(self.filter, name.as_ptr(), value) };
    }

    fn set_int(&self, name: &CStr, value: c_int) {
        // SAFETY: as `set_bool`.
        unsafe { (self.device.oidn.set_filter_int)(self.filter, name.as_ptr(), value) };
    }

    /// Commits and executes the filter, then reports the device's error.
    fn run(&self) -> Result<(), String> {
        // SAFETY: a live filter whose images are live (see `image`).
        unsafe {
            (self.device.oidn.commit_filter)(self.filter);
        }
        self.device.check()?;
        // SAFETY: as above.
        unsafe {
            (self.device.oidn.execute_filter)(self.filter);
        }
        self.device.check()
    }
}

impl Drop for FilterGuard<'_, '_> {
    fn drop(&mut self) {
        // SAFETY: a filter made by `DeviceGuard::filter`, released once.
        unsafe { (self.device.oidn.release_filter)(self.filter) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rpbrt-oidn-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    }

    #[test]
    fn a_missing_library_says_how_to_install_it() {
        let d = temp_dir("missing");
        let cands: Vec<(PathBuf, bool)> = NAMES.iter().map(|n| (d.join(n), true)).collect();
        let Err(e) = Oidn::load_from(&cands) else {
            panic!("an empty folder gave a library");
        };
        assert!(
            e.contains("not found") && e.contains("pip install pyoidn"),
            "{e}"
        );
    }

    #[test]
    fn a_corrupt_library_is_an_error_naming_it() {
        let d = temp_dir("corrupt");
        let f = d.join(NAMES[0]);
        std::fs::write(&f, b"\x7fELF this is not a shared library").expect("write");
        let Err(e) = Oidn::load_from(&[(f.clone(), true)]) else {
            panic!("a corrupt file loaded");
        };
        assert!(
            e.contains(&f.display().to_string()) && e.contains("cannot load"),
            "{e}"
        );
    }

    #[test]
    fn a_library_without_oidn_is_not_taken_for_it() {
        // The C library loads but lacks OIDN's functions.
        let Err(e) = Oidn::open(Path::new("libc.so.6")) else {
            panic!("libc taken for OIDN");
        };
        assert!(e.contains("not an Open Image Denoise library"), "{e}");
    }

    #[test]
    fn quality_names() {
        assert_eq!(Quality::parse("fast"), Some(Quality::Fast));
        assert_eq!(Quality::parse("high").map(Quality::value), Some(6));
        assert_eq!(Quality::parse("best"), None);
    }
}
