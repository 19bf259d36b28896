//! On-disk cache of CPU reference images (and, in [`probes`], baked light probes): a reference
//! render takes minutes, so it is stored under a key derived from everything that determines it
//! ([`scene_fingerprint`], camera, settings) and reused while that is unchanged.
//!
//! Each entry is `<key>.bin` (magic `STRATAREF2` naming the format version, then width, height,
//! channels as little-endian `u32`, the 64-bit FNV-1a checksum of the data, then the float data as
//! little-endian `f32`, bit-exact) and `<key>.txt` holding the description the key was derived
//! from, for humans. Both are written atomically. An entry that is truncated, corrupt (checksum)
//! or of an older format version is reported and recomputed.

use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use strata_scene::{ImageBuf, Scene};

pub mod converged;
pub mod environment;
pub mod probes;

/// Most channels an entry may have: the widest estimator's, the screen oracle's means
/// (converged GI halves hold 6: direct and indirect RGB). `store` refuses wider images, so
/// nothing is stored that `load` would then reject.
const MAX_CHANNELS: u32 = strata_reference::oracle::ORACLE_CHANNELS;

const MAGIC: &[u8; 10] = b"STRATAREF2";
/// Magic + width, height, channels + checksum.
const HEADER_LEN: usize = MAGIC.len() + 12 + 8;

/// A directory of cached reference images.
#[derive(Clone, Debug)]
pub struct RefCache {
    dir: PathBuf,
}

impl RefCache {
    /// A cache in `dir` (created when the first entry is stored).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The cache's directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `$STRATA_CACHE` if set, else `$XDG_CACHE_HOME/strata/reference`, else
    /// `$HOME/.cache/strata/reference`, else `./.strata-cache`. Empty variables count as unset.
    pub fn default_dir() -> PathBuf {
        default_dir_from(|name| std::env::var_os(name))
    }

    /// The stable cache key of `description`: its 64-bit FNV-1a hash as 16 lowercase hex digits.
    ///
    /// The caller makes the description contain everything that determines the reference image:
    /// the scene (a hash of the scene file's bytes, or the built-in scene's name), the camera, the
    /// image size, the frame, every reference setting (kind, spp, bounces, seed, ...) and a format
    /// version to bump when the renderer's output changes.
    pub fn key(description: &str) -> String {
        format!("{:016x}", fnv1a64(description.as_bytes()))
    }

    /// The cached image for `key`, or `None` when there is none or it cannot be used (a missing
    /// entry is silent; an unreadable or corrupt one is logged with `tracing::warn!`).
    pub fn load(&self, key: &str) -> Option<ImageBuf> {
        if !valid_key(key) {
            tracing::warn!("reference cache: invalid key {key:?}");
            return None;
        }
        let path = self.bin_path(key);
        let bytes = match fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
            Err(e) => {
                tracing::warn!("reference cache: cannot read {}: {e}", path.display());
                return None;
            }
        };
        match decode(&bytes) {
            Ok(img) => Some(img),
            Err(e) => {
                tracing::warn!("reference cache: ignoring corrupt {}: {e}", path.display());
                None
            }
        }
    }

    /// Stores `img` under `key` (atomically: a temporary file renamed into place) with
    /// `description` beside it; returns the path of the `.bin` file.
    pub fn store(&self, key: &str, img: &ImageBuf, description: &str) -> Result<PathBuf> {
        if !valid_key(key) {
            bail!("reference cache: invalid key {key:?}: use ASCII letters, digits, '-' or '_'");
        }
        if !(1..=MAX_CHANNELS).contains(&img.channels) {
            bail!(
                "reference cache: image has {} channels: expected 1 to {MAX_CHANNELS}",
                img.channels
            );
        }
        let expected = img.width as usize * img.height as usize * img.channels as usize;
        if img.data.len() != expected {
            bail!(
                "reference cache: image holds {} values but {}x{} with {} channel(s) needs {expected}",
                img.data.len(),
                img.width,
                img.height,
                img.channels
            );
        }
        fs::create_dir_all(&self.dir)
            .with_context(|| format!("{}: cannot create the reference cache directory", self.dir.display()))?;

        let path = self.bin_path(key);
        strata_scene::atomic::write(&path, &encode(img)).map_err(|e| anyhow::anyhow!("reference cache: {e}"))?;
        let txt = self.dir.join(format!("{key}.txt"));
        strata_scene::atomic::write(&txt, description.as_bytes())
            .map_err(|e| anyhow::anyhow!("reference cache: {e}"))?;
        Ok(path)
    }

    /// Stores `value` as JSON in `<key>.json` (atomically): metadata beside an image entry.
    pub fn store_json<T: serde::Serialize>(&self, key: &str, value: &T) -> Result<PathBuf> {
        if !valid_key(key) {
            bail!("reference cache: invalid key {key:?}: use ASCII letters, digits, '-' or '_'");
        }
        fs::create_dir_all(&self.dir)
            .with_context(|| format!("{}: cannot create the reference cache directory", self.dir.display()))?;
        let path = self.dir.join(format!("{key}.json"));
        let text = serde_json::to_vec(value)?;
        strata_scene::atomic::write(&path, &text).map_err(|e| anyhow::anyhow!("reference cache: {e}"))?;
        Ok(path)
    }

    /// The JSON stored by [`RefCache::store_json`] under `key`, or `None` when there is none or it
    /// does not parse as `T` (logged).
    pub fn load_json<T: serde::de::DeserializeOwned>(&self, key: &str) -> Option<T> {
        if !valid_key(key) {
            return None;
        }
        let path = self.dir.join(format!("{key}.json"));
        let bytes = fs::read(&path).ok()?;
        match serde_json::from_slice(&bytes) {
            Ok(v) => Some(v),
            Err(e) => {
                tracing::warn!("reference cache: ignoring unreadable {}: {e}", path.display());
                None
            }
        }
    }

    fn bin_path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.bin"))
    }

    /// The image for `description`, from the cache (unless `refresh`) or computed and stored
    /// (a failure to store is logged, not fatal).
    pub fn get_or_compute(&self, refresh: bool, description: &str, compute: impl FnOnce() -> ImageBuf) -> ImageBuf {
        let key = RefCache::key(description);
        if !refresh {
            if let Some(img) = self.load(&key) {
                tracing::info!("reference {key} from {}", self.dir.display());
                return img;
            }
        }
        let img = compute();
        self.store_or_warn(&key, &img, description);
        img
    }

    /// [`RefCache::store`], logging a failure instead of returning it.
    pub fn store_or_warn(&self, key: &str, img: &ImageBuf, description: &str) {
        if let Err(e) = self.store(key, img, description) {
            tracing::warn!("could not cache the reference: {e:#}");
        }
    }
}

/// Identifies a scene's content at one frame for cache keys: name, triangle count, an FNV-1a hash
/// of every vertex position and index, the materials, the object transforms at `frame`, and the
/// scene settings.
pub fn scene_fingerprint(scene: &Scene, frame: f32) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    };
    for m in &scene.meshes {
        eat(bytemuck::cast_slice(&m.positions));
        eat(bytemuck::cast_slice(&m.indices));
        eat(&(m.material as u64).to_le_bytes());
    }
    for o in &scene.objects {
        eat(bytemuck::cast_slice(&o.transform_at(frame).to_cols_array()));
        eat(&(o.mesh as u64).to_le_bytes());
    }
    eat(format!(
        "{}{}",
        materials_fingerprint(&scene.materials),
        settings_fingerprint(&scene.settings)
    )
    .as_bytes());
    format!("scene={} tris={} geometry={h:016x}", scene.name, scene.triangle_count(),)
}

/// The materials as text for [`scene_fingerprint`]: the fields every material had
/// when converged references were first cached, in their `Debug` form (so those
/// keys stay valid), then each later field only where it differs from its
/// default — a field added to the model changes no key of a scene that does not
/// use it, and every key of one that does.
fn materials_fingerprint(materials: &[strata_scene::Material]) -> String {
    let one = |m: &strata_scene::Material| {
        let mut t = format!(
            "Material {{ name: {:?}, base_color: {:?}, base_color_texture: {:?}, emission: {:?}, opacity: {:?}, roughness: {:?}, metallic: {:?} }}",
            m.name, m.base_color, m.base_color_texture, m.emission, m.opacity, m.roughness, m.metallic
        );
        if let Some(c) = m.alpha_cutoff {
            t += &format!(" alpha_cutoff={c:?}");
        }
        if m.texture_alpha {
            t += " texture_alpha";
        }
        if m.glossy {
            t += " glossy";
        }
        t
    };
    format!("[{}]", materials.iter().map(one).collect::<Vec<_>>().join(", "))
}

/// The scene settings as text for [`scene_fingerprint`], by the rule of
/// [`materials_fingerprint`]: the fields settings had when converged references were first
/// cached, in their `Debug` form, then each later field only where it is set.
fn settings_fingerprint(s: &strata_scene::SceneSettings) -> String {
    let mut t = format!(
        "SceneSettings {{ ao_radius: {:?}, min_separation: {:?}, radiosity_radius: {:?}, exposure: {:?}, sky: {:?}, ambient: {:?} }}",
        s.ao_radius, s.min_separation, s.radiosity_radius, s.exposure, s.sky, s.ambient
    );
    if let Some(b) = s.probe_bounds {
        t += &format!(" probe_bounds={b:?}");
    }
    t
}

/// [`RefCache::default_dir`] with the environment given as a function (testable without touching
/// the process environment).
fn default_dir_from(var: impl Fn(&str) -> Option<OsString>) -> PathBuf {
    let var = |name: &str| var(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    if let Some(dir) = var("STRATA_CACHE") {
        dir
    } else if let Some(dir) = var("XDG_CACHE_HOME") {
        dir.join("strata").join("reference")
    } else if let Some(home) = var("HOME") {
        home.join(".cache").join("strata").join("reference")
    } else {
        PathBuf::from(".strata-cache")
    }
}

/// 64-bit FNV-1a.
fn fnv1a64(bytes: &[u8]) -> u64 {
    const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    bytes
        .iter()
        .fold(OFFSET_BASIS, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

/// Keys become file names: keep them to a safe alphabet (no separators, no `..`).
fn valid_key(key: &str) -> bool {
    !key.is_empty() && key.len() <= 128 && key.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
}

fn encode(img: &ImageBuf) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + img.data.len() * 4);
    out.extend_from_slice(MAGIC);
    for v in [img.width, img.height, img.channels] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let payload: Vec<u8> = img.data.iter().flat_map(|v| v.to_le_bytes()).collect();
    out.extend_from_slice(&fnv1a64(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

fn decode(bytes: &[u8]) -> std::result::Result<ImageBuf, String> {
    if bytes.len() < HEADER_LEN {
        return Err(format!(
            "{} bytes is shorter than the {HEADER_LEN}-byte header",
            bytes.len()
        ));
    }
    if &bytes[..MAGIC.len() - 1] == b"STRATAREF" && bytes[MAGIC.len() - 1] != MAGIC[MAGIC.len() - 1] {
        return Err(format!(
            "format version {} is not the current {}",
            bytes[MAGIC.len() - 1] as char,
            MAGIC[MAGIC.len() - 1] as char
        ));
    }
    if &bytes[..MAGIC.len()] != MAGIC {
        return Err("wrong magic: not a STRATAREF file".into());
    }
    let u32_at = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let (width, height, channels) = (u32_at(10), u32_at(14), u32_at(18));
    if !(1..=MAX_CHANNELS).contains(&channels) {
        return Err(format!("{channels} channels: expected 1 to {MAX_CHANNELS}"));
    }
    let payload = &bytes[HEADER_LEN..];
    let stored = u64::from_le_bytes(bytes[22..30].try_into().expect("8 bytes"));
    let count = (width as usize)
        .checked_mul(height as usize)
        .and_then(|n| n.checked_mul(channels as usize))
        .filter(|n| n.checked_mul(4) == Some(payload.len()))
        .ok_or_else(|| {
            format!(
                "{width}x{height} with {channels} channel(s) does not match the {} data bytes",
                payload.len()
            )
        })?;
    if fnv1a64(payload) != stored {
        return Err("checksum mismatch: the data is corrupt".into());
    }
    let data = payload
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect::<Vec<_>>();
    debug_assert_eq!(data.len(), count);
    Ok(ImageBuf {
        width,
        height,
        channels,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh, empty directory under the system temp dir, removed when dropped.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> Self {
            let nanos = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos());
            let dir = std::env::temp_dir().join(format!("strata-ref-cache-{name}-{}-{nanos}", std::process::id()));
            fs::create_dir_all(&dir).unwrap();
            Self(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    fn sample() -> ImageBuf {
        let mut img = ImageBuf::new(5, 3, 3);
        for (i, v) in img.data.iter_mut().enumerate() {
            *v = (i as f32 * 0.377).sin() * 10.0;
        }
        // Values whose bits a lossy format would not keep.
        img.data[0] = -0.0;
        img.data[1] = f32::MIN_POSITIVE / 8.0;
        img.data[2] = f32::INFINITY;
        img.data[3] = f32::from_bits(0x7fc0_1234);
        img
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let tmp = TempDir::new("roundtrip");
        let cache = RefCache::new(tmp.0.join("nested"));
        let img = sample();
        let key = RefCache::key("cornell ao 16spp 5x3");
        assert!(cache.load(&key).is_none());
        let path = cache.store(&key, &img, "cornell ao 16spp 5x3").unwrap();
        assert_eq!(path, tmp.0.join("nested").join(format!("{key}.bin")));
        assert_eq!(
            fs::read_to_string(tmp.0.join("nested").join(format!("{key}.txt"))).unwrap(),
            "cornell ao 16spp 5x3"
        );
        let back = cache.load(&key).unwrap();
        assert_eq!((back.width, back.height, back.channels), (5, 3, 3));
        let bits = |d: &[f32]| d.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.data), bits(&img.data));
        // No temporary file is left behind.
        let names: Vec<_> = fs::read_dir(tmp.0.join("nested"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }

    #[test]
    fn truncated_or_corrupt_files_load_as_none() {
        let tmp = TempDir::new("corrupt");
        let cache = RefCache::new(&tmp.0);
        let key = RefCache::key("x");
        let path = cache.store(&key, &sample(), "x").unwrap();
        let bytes = fs::read(&path).unwrap();
        for cut in [0, 5, HEADER_LEN - 1, HEADER_LEN, bytes.len() - 1] {
            fs::write(&path, &bytes[..cut]).unwrap();
            assert!(cache.load(&key).is_none(), "truncated to {cut} bytes");
        }
        let mut bad_magic = bytes.clone();
        bad_magic[0] = b'X';
        fs::write(&path, &bad_magic).unwrap();
        assert!(cache.load(&key).is_none());
        let mut huge = bytes.clone();
        huge[10..14].copy_from_slice(&u32::MAX.to_le_bytes());
        huge[14..18].copy_from_slice(&u32::MAX.to_le_bytes());
        fs::write(&path, &huge).unwrap();
        assert!(cache.load(&key).is_none());
        fs::write(&path, &bytes).unwrap();
        assert!(cache.load(&key).is_some());
    }

    #[test]
    fn flipped_bits_and_old_format_versions_are_detected() {
        let tmp = TempDir::new("checksum");
        let cache = RefCache::new(&tmp.0);
        let key = RefCache::key("y");
        let path = cache.store(&key, &sample(), "y").unwrap();
        let bytes = fs::read(&path).unwrap();
        // same length, one bit of one float changed: only the checksum can tell
        let mut flipped = bytes.clone();
        *flipped.last_mut().unwrap() ^= 0x01;
        assert!(decode(&flipped).unwrap_err().contains("checksum"));
        fs::write(&path, &flipped).unwrap();
        assert!(cache.load(&key).is_none());
        let mut v1 = bytes.clone();
        v1[9] = b'1';
        assert!(decode(&v1).unwrap_err().contains("format version 1"));
        // storing again repairs the entry
        cache.store(&key, &sample(), "y").unwrap();
        assert!(cache.load(&key).is_some());
    }

    #[test]
    fn material_fingerprint_is_the_old_debug_text_until_a_new_field_is_set() {
        let mut m = vec![strata_scene::Material::diffuse("a", [0.5, 0.25, 1.0])];
        let old = format!(
            "[Material {{ name: \"a\", base_color: [0.5, 0.25, 1.0], base_color_texture: None, emission: [0.0, 0.0, 0.0], opacity: 1.0, roughness: {:?}, metallic: 0.0 }}]",
            m[0].roughness
        );
        assert_eq!(materials_fingerprint(&m), old);
        m[0].alpha_cutoff = Some(0.5);
        assert_ne!(materials_fingerprint(&m), old);
        m[0].alpha_cutoff = None;
        m[0].texture_alpha = true;
        assert_ne!(materials_fingerprint(&m), old);
        m[0].texture_alpha = false;
        m[0].glossy = true;
        assert_ne!(materials_fingerprint(&m), old);
    }

    #[test]
    fn settings_fingerprint_is_the_old_debug_text_until_a_new_field_is_set() {
        // `probe_bounds` (added 2026-11-27) first changed every scene's key, and with it
        // every cached converged reference
        let mut s = strata_scene::SceneSettings {
            sky: [0.25, 0.5, 1.0],
            ..Default::default()
        };
        let old = "SceneSettings { ao_radius: 1.0, min_separation: 0.5, radiosity_radius: 8.0, exposure: 1.0, sky: [0.25, 0.5, 1.0], ambient: [0.03, 0.03, 0.03] }";
        assert_eq!(settings_fingerprint(&s), old);
        s.probe_bounds = Some([[0.0; 3], [1.0; 3]]);
        assert_ne!(settings_fingerprint(&s), old);
    }

    #[test]
    fn keys_are_stable_fnv1a_and_distinguish_descriptions() {
        assert_eq!(RefCache::key(""), "cbf29ce484222325");
        assert_eq!(RefCache::key("a"), "af63dc4c8601ec8c");
        assert_eq!(RefCache::key("foobar"), "85944171f73967e8");
        let a = RefCache::key("scene=cornell spp=16 size=64x64 v1");
        let b = RefCache::key("scene=cornell spp=17 size=64x64 v1");
        assert_ne!(a, b);
        assert_eq!(a, RefCache::key("scene=cornell spp=16 size=64x64 v1"));
        assert_eq!(a.len(), 16);
    }

    #[test]
    fn invalid_keys_and_images_are_rejected() {
        let tmp = TempDir::new("invalid");
        let cache = RefCache::new(&tmp.0);
        assert!(cache.store("../escape", &sample(), "").is_err());
        assert!(cache.store("", &sample(), "").is_err());
        assert!(cache.load("../escape").is_none());
        let mut short = sample();
        short.data.pop();
        assert!(cache.store("abc", &short, "").is_err());
        let wide = ImageBuf::new(2, 2, MAX_CHANNELS + 1);
        let e = format!("{:#}", cache.store("wide", &wide, "").unwrap_err());
        assert!(e.contains(&format!("expected 1 to {MAX_CHANNELS}")), "{e}");
        assert!(cache.load("wide").is_none());
    }

    /// Every estimator's means are stored and read back: the screen oracle's 64 channels were
    /// once refused on loading, so its converged images were recomputed on every run.
    #[test]
    fn every_estimators_channel_count_round_trips() {
        use strata_reference::{oracle::ScreenOracleSettings, Estimator};
        let tmp = TempDir::new("channels");
        let cache = RefCache::new(&tmp.0);
        for estimator in [
            Estimator::AoBinary(Default::default()),
            Estimator::Obscurance(Default::default()),
            Estimator::Gi(Default::default()),
            Estimator::ScreenOracle(ScreenOracleSettings {
                gi: Default::default(),
                min_separation: 0.1,
                radius: 1.0,
            }),
        ] {
            let n = estimator.channels();
            let mut img = ImageBuf::new(3, 2, n);
            for (i, v) in img.data.iter_mut().enumerate() {
                *v = i as f32 * 0.5 - 1.0;
            }
            let key = format!("est{n}");
            cache.store(&key, &img, "").unwrap();
            let back = cache
                .load(&key)
                .unwrap_or_else(|| panic!("{estimator:?}: not read back"));
            assert_eq!((back.channels, back.data), (n, img.data), "{estimator:?}");
        }
    }

    #[test]
    fn store_error_names_the_path() {
        let tmp = TempDir::new("blocked");
        let blocker = tmp.0.join("file");
        fs::write(&blocker, b"not a directory").unwrap();
        let cache = RefCache::new(blocker.join("sub"));
        let e = format!("{:#}", cache.store("abc", &sample(), "").unwrap_err());
        assert!(e.contains(&blocker.display().to_string()), "{e}");
    }

    #[test]
    fn default_dir_precedence() {
        let env = |vars: &'static [(&'static str, &'static str)]| {
            move |name: &str| vars.iter().find(|(k, _)| *k == name).map(|(_, v)| OsString::from(v))
        };
        assert_eq!(
            default_dir_from(env(&[("STRATA_CACHE", "/c"), ("XDG_CACHE_HOME", "/x"), ("HOME", "/h")])),
            PathBuf::from("/c")
        );
        assert_eq!(
            default_dir_from(env(&[("STRATA_CACHE", ""), ("XDG_CACHE_HOME", "/x"), ("HOME", "/h")])),
            PathBuf::from("/x/strata/reference")
        );
        assert_eq!(
            default_dir_from(env(&[("HOME", "/h")])),
            PathBuf::from("/h/.cache/strata/reference")
        );
        assert_eq!(default_dir_from(env(&[])), PathBuf::from(".strata-cache"));
    }
}
