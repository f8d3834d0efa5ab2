//! Reading a scene file: bounded in size, UTF-8, and dispatched by its format (`.xml` is a
//! Mitsuba 3 scene, anything else mfh's JSON). Apart from `scene.rs` so that the scene types
//! import no format reader: the readers (`mitsuba.rs`, …) build scenes, this file picks one.

use crate::scene::{Scene, SceneError, MAX_SCENE_BYTES};
use std::path::Path;

impl Scene {
    /// Reads a scene file of at most [`MAX_SCENE_BYTES`] (read bounded: a larger file or an
    /// endless stream is refused after the limit): `.xml` is a Mitsuba 3 scene
    /// (`mitsuba.rs`, feature `mitsuba`), anything else mfh's JSON.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        use std::io::Read;
        let unreadable = |e: std::io::Error| SceneError::Unreadable {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        let file = std::fs::File::open(path).map_err(unreadable)?;
        let mut bytes = Vec::new();
        file.take(MAX_SCENE_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(unreadable)?;
        if bytes.len() as u64 > MAX_SCENE_BYTES {
            return Err(SceneError::TooLarge {
                path: path.display().to_string(),
                limit: MAX_SCENE_BYTES,
            });
        }
        let text = String::from_utf8(bytes).map_err(|e| SceneError::Unreadable {
            path: path.display().to_string(),
            message: format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        })?;
        let is_xml = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
        if is_xml {
            #[cfg(feature = "mitsuba")]
            return crate::mitsuba::parse(&text, &path.display().to_string());
            #[cfg(not(feature = "mitsuba"))]
            return Err(SceneError::FeatureOff {
                path: path.display().to_string(),
                feature: "mitsuba",
            });
        }
        Scene::parse(&text, &path.display().to_string())
    }
}
