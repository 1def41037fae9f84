//! The one runtime choice of backend: a burn `Device` made from the config's `device` (or the
//! command line's `--device`).

use crate::config::DeviceChoice;
use burn::tensor::{Device, Tensor};

/// The device for `choice`, with autodiff enabled (tensors made on it can be differentiated).
///
/// For `wgpu` a one-element tensor is made and read back first, so that a machine without a
/// usable adapter gets a one-line [`Error::Usage`](crate::Error::Usage) here rather than a
/// panic deep inside the first render.
pub fn device(choice: DeviceChoice) -> crate::Result<Device> {
    match choice {
        DeviceChoice::Flex => Ok(Device::flex().autodiff()),
        DeviceChoice::Wgpu => {
            let device = Device::wgpu(burn::tensor::DeviceKind::DefaultDevice);
            probe(&device).map_err(|why| {
                crate::Error::Usage(format!(
                    "device wgpu: no usable GPU adapter ({why}); use `--device flex` (CPU), or install a Vulkan, Metal, DX12 or OpenGL driver"
                ))
            })?;
            Ok(device.autodiff())
        }
    }
}

/// A tensor's values read back to the host, as `f32` in row-major order.
pub fn host_values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().convert::<f32>().try_to_vec::<f32>().expect("float tensor data")
}

/// Makes and reads back one tensor on `device`; if that panics (here or in the backend's own
/// threads), the first panic's first line.
fn probe(device: &Device) -> Result<(), String> {
    use std::sync::{Arc, Mutex};
    let first: Arc<Mutex<Option<String>>> = Arc::default();
    let hook = std::panic::take_hook();
    let record = first.clone();
    std::panic::set_hook(Box::new(move |info| {
        let text = info
            .payload()
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| info.payload().downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "the backend panicked".into());
        record.lock().map(|mut slot| slot.get_or_insert(text.lines().next().unwrap_or_default().to_string()).clone()).ok();
    }));
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        Tensor::<1>::zeros([1], device).into_data();
    }));
    std::panic::set_hook(hook);
    let first = first.lock().ok().and_then(|mut slot| slot.take());
    outcome.map_err(|_| first.unwrap_or_else(|| "the backend panicked".into()))
}
