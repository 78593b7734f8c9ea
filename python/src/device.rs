//! Which evaluator a query runs on. The GPU is opened once per process and shared by every
//! stage (its pipelines are compiled once); a missing adapter is remembered too. `device="auto"`
//! (DESIGN.md §4) is decided once per process: a hardware adapter, else the CPU reference with
//! one `DeviceWarning` saying why (a software adapter such as lavapipe only with "gpu").

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use luxeval::{Evaluator, LuxError, TemperatureMode, TextureFilter};
use pyo3::prelude::*;

use crate::errors::{self, DeviceError, DeviceWarning};

/// The `device=` argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Device {
    Auto,
    Gpu,
    Cpu,
}

impl Device {
    pub fn parse(s: &str) -> PyResult<Device> {
        match s {
            "auto" => Ok(Device::Auto),
            "gpu" => Ok(Device::Gpu),
            "cpu" => Ok(Device::Cpu),
            other => Err(errors::input(format!(
                "device: {other:?} is not one of \"auto\", \"gpu\", \"cpu\""
            ))),
        }
    }
}

/// The `temperature_mode=` argument.
pub fn parse_mode(s: &str) -> PyResult<TemperatureMode> {
    match s {
        "spec" => Ok(TemperatureMode::Spec),
        "usd" => Ok(TemperatureMode::Usd),
        "planckian" => Ok(TemperatureMode::Planckian),
        other => Err(errors::input(format!(
            "temperature_mode: {other:?} is not one of \"spec\", \"usd\", \"planckian\""
        ))),
    }
}

/// The `portal_mode=` argument (the CLI's `--portal-mode`, DESIGN.md §8 P2).
pub fn parse_portal_mode(s: &str) -> PyResult<luxeval::PortalMode> {
    s.parse::<luxeval::PortalMode>().map_err(|_| {
        errors::input(format!(
            "portal_mode: {s:?} is not one of \"hint\", \"mask\""
        ))
    })
}

/// The `texture_filter=` argument (the CLI's `--texture-filter`).
pub fn parse_filter(s: &str) -> PyResult<TextureFilter> {
    match s {
        "bilinear" => Ok(TextureFilter::Bilinear),
        "nearest" => Ok(TextureFilter::Nearest),
        other => Err(errors::input(format!(
            "texture_filter: {other:?} is not one of \"bilinear\", \"nearest\""
        ))),
    }
}

pub fn filter_name(f: TextureFilter) -> &'static str {
    match f {
        TextureFilter::Bilinear => "bilinear",
        TextureFilter::Nearest => "nearest",
    }
}

pub fn mode_name(m: TemperatureMode) -> &'static str {
    match m {
        TemperatureMode::Spec => "spec",
        TemperatureMode::Usd => "usd",
        TemperatureMode::Planckian => "planckian",
    }
}

enum Gpu {
    Ready(Evaluator),
    /// No adapter: the reason wgpu gave.
    Missing(String),
}

static GPU: Mutex<Option<Gpu>> = Mutex::new(None);
/// What `device="auto"` chose, and why.
static AUTO: Mutex<Option<(Evaluator, String)>> = Mutex::new(None);
static WARNED: AtomicBool = AtomicBool::new(false);

/// The process's GPU evaluator, opened on first use (with the GIL released), or why there is
/// none. Errors other than a missing adapter are not remembered: the next call tries again.
fn gpu(py: Python<'_>) -> PyResult<Result<Evaluator, String>> {
    let r = py.detach(|| {
        let mut g = GPU
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if g.is_none() {
            match Evaluator::gpu() {
                Ok(e) => *g = Some(Gpu::Ready(e)),
                Err(LuxError::NoAdapter { reason, .. }) => *g = Some(Gpu::Missing(reason)),
                Err(e) => return Err(e),
            }
        }
        Ok(match g.as_ref() {
            Some(Gpu::Ready(e)) => Ok(e.clone()),
            Some(Gpu::Missing(reason)) => Err(reason.clone()),
            None => unreachable!("set above"),
        })
    });
    r.map_err(|e| errors::lux(e, None))
}

/// The process's `device="auto"` evaluator and why it was chosen, decided on first use (with the
/// GIL released).
fn auto(py: Python<'_>) -> PyResult<(Evaluator, String)> {
    let r = py.detach(|| {
        let mut a = AUTO
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if a.is_none() {
            *a = Some(Evaluator::auto()?);
        }
        Ok(a.clone().expect("set above"))
    });
    r.map_err(|e| errors::lux(e, None))
}

/// The evaluator for `device`: the GPU (an error without one), the CPU reference, or (`auto`) a
/// hardware GPU, else the CPU reference with one `DeviceWarning` per process.
pub fn evaluator(py: Python<'_>, device: Device, mode: TemperatureMode) -> PyResult<Evaluator> {
    let eval = match device {
        Device::Cpu => Evaluator::cpu(),
        Device::Gpu => match gpu(py)? {
            Ok(e) => e,
            Err(reason) => return Err(DeviceError::new_err(no_adapter(&reason))),
        },
        Device::Auto => {
            let (eval, why) = auto(py)?;
            if !eval.is_gpu() && !WARNED.swap(true, Ordering::SeqCst) {
                errors::warn::<DeviceWarning>(py, &format!("device=\"auto\": {why}"))?;
            }
            eval
        }
    };
    Ok(eval.with_temperature_mode(mode))
}

fn no_adapter(reason: &str) -> String {
    format!(
        "no GPU adapter found ({reason}); use device=\"cpu\" or \"auto\", or install a Vulkan \
         driver (e.g. Mesa's lavapipe: mesa-vulkan-drivers)"
    )
}

/// The device a query with this ``device=`` argument runs on: the GPU adapter's name and
/// backend (e.g. ``"llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)"``) or ``"cpu (f64 reference)"``.
/// Opens the GPU if it is not open yet (``device="auto"`` is the CPU reference, with a
/// ``DeviceWarning`` saying why, when there is no hardware adapter; ``device="gpu"`` raises
/// ``DeviceError`` when there is no adapter at all).
#[pyfunction]
#[pyo3(signature = (device = "auto"))]
pub fn device_name(py: Python<'_>, device: &str) -> PyResult<String> {
    let d = Device::parse(device)?;
    Ok(evaluator(py, d, TemperatureMode::Spec)?.device_name())
}
