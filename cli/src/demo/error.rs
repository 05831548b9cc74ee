//! Why the demo stops ([`DemoError`], and [`SceneError`] for a scene that cannot be used) and
//! the one way it writes an image: every layer of the demo (fixtures, measures, report) returns
//! these.

use std::path::Path;

use lodkit::gpu::GpuError;
use lodkit::shaders::ShaderError;

/// Why the demo stopped.
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// No GPU adapter at all.
    #[error(
        "{source}\n\nlodkit demo needs a GPU adapter: a GPU driver with Vulkan, or the software \
         rasterizers. On Debian/Ubuntu: `sudo apt-get install mesa-vulkan-drivers libvulkan1` \
         (lavapipe); for OpenGL, `libegl1 libgl1-mesa-dri` and LODKIT_BACKEND=gl. On a desktop \
         without a session bus set XDG_RUNTIME_DIR to a private folder."
    )]
    NoAdapter {
        /// What wgpu said.
        #[source]
        source: GpuError,
    },
    /// The device could not be created.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A lodkit pass did not compose (a bug: please report it).
    #[error("a lodkit pass does not compose: {0}")]
    Shader(#[from] ShaderError),
    /// The scene file.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// An option out of range.
    #[error("{0}")]
    Options(String),
    /// Writing output.
    #[error("{path}: {message}")]
    Io {
        /// The file or folder.
        path: String,
        /// What failed.
        message: String,
    },
    /// Drawing a plot.
    #[error("plot: {0}")]
    Plot(String),
    /// An inconsistency inside the harness.
    #[error("internal: {0}")]
    Internal(String),
}

impl DemoError {
    pub(crate) fn io(path: &Path, e: impl std::fmt::Display) -> Self {
        DemoError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    }
}

/// Saves `image` as PNG at `path`, creating folders.
pub fn save(image: &image::RgbaImage, path: &Path) -> Result<(), DemoError> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| DemoError::io(dir, e))?;
    }
    image.save(path).map_err(|e| DemoError::io(path, e))
}

/// A scene file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// RON syntax or a field of the wrong type.
    #[error("{path}:{line}:{column}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// Values that parse but cannot be rendered.
    #[error("{path}: {message}")]
    Invalid {
        /// The file (or `built-in`).
        path: String,
        /// What is wrong and where (`objects[3].scale`, ...).
        message: String,
    },
}
