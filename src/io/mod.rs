//! Files in and out: scene folders, `parameters.cfg`, PFM maps, PNG/EXR images, motion files and
//! ground truth, all as FORMAT conventions define them. Every error names its file.

mod atomic;
mod error;
mod ground_truth;
mod image_file;
mod motion_file;
mod params;
mod pfm;
mod raster;
mod scene;

pub use atomic::{create_dir_all, write_atomic, write_folder};
pub use error::{IoError, IoResult};
pub use ground_truth::{GroundTruth, read_if_present};
pub use image_file::{read_image, write_mask_png, write_png};
pub use motion_file::MotionRecord;
pub use params::SceneParameters;
pub use pfm::{decode_pfm, encode_pfm, read_pfm, write_pfm};
pub use raster::Raster;
pub use scene::{Scene, view_file_name};
