//! The one runtime choice of backend: a burn `Device` made from the config's `device`.

use crate::config::DeviceChoice;
use burn::tensor::Device;

/// The device for `choice`, with autodiff enabled (tensors made on it can be differentiated).
pub fn device(choice: DeviceChoice) -> Device {
    let base = match choice {
        DeviceChoice::Flex => Device::flex(),
        DeviceChoice::Wgpu => Device::wgpu(burn::tensor::DeviceKind::DefaultDevice),
    };
    base.autodiff()
}
