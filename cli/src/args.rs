//! Arguments shared by several commands, and their parsers.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use luxeval::{Accumulate, PortalMode, TemperatureMode, TextureFilter};

/// The stage, light selection, time, colour-temperature mode and texture filter every scene
/// command takes.
#[derive(Args)]
pub struct SceneArgs {
    /// The stage: .usda, .usdc or .usdz.
    pub scene: PathBuf,
    /// Evaluate only this light (prim path); repeatable. Default: every visible light that luxeval
    /// evaluates, in stage order.
    #[arg(long = "light", value_name = "PATH")]
    pub lights: Vec<String>,
    #[command(flatten)]
    pub time: TimeArg,
    /// How colorTemperature becomes RGB: spec (6500 K is white), usd (Pixar's
    /// UsdLux.BlackbodyTemperatureAsRgb), planckian (the OpenUSD reference renderer's path).
    #[arg(long, value_enum, default_value_t = ModeArg::Spec)]
    pub temperature_mode: ModeArg,
    /// How dome and rect textures are reconstructed between texel centres: bilinear, or the
    /// nearest texel. Irradiance integrates the reconstruction chosen.
    #[arg(long, value_enum, default_value_t = FilterArg::Bilinear)]
    pub texture_filter: FilterArg,
    #[command(flatten)]
    pub portal: PortalArg,
}

/// `--portal-mode` (DESIGN.md §8 P2), shared by the scene commands and `lights`.
#[derive(Args, Clone, Copy)]
pub struct PortalArg {
    /// How a dome's PortalLights are read: hint (they guide sampling only and change no value),
    /// or mask (the dome reaches a point only through its portals, times each portal's
    /// multiplier).
    #[arg(long = "portal-mode", value_enum, default_value_t = PortalArgMode::Hint)]
    pub portal_mode: PortalArgMode,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum PortalArgMode {
    Hint,
    Mask,
}

impl From<PortalArgMode> for PortalMode {
    fn from(m: PortalArgMode) -> Self {
        match m {
            PortalArgMode::Hint => PortalMode::Hint,
            PortalArgMode::Mask => PortalMode::Mask,
        }
    }
}

/// Options shared by the array queries.
#[derive(Args)]
pub struct QueryArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// One result per light, shape (L, N, 3), in the order `luxeval lights` lists them, instead of
    /// the sum over lights.
    #[arg(long)]
    pub per_light: bool,
    /// Where to evaluate. Default `auto`: a hardware GPU adapter when there is one, else the CPU
    /// reference (a software adapter such as lavapipe only with `--device gpu`).
    #[arg(long, value_enum)]
    pub device: Option<DeviceArg>,
}

impl QueryArgs {
    pub fn accumulate(&self) -> Accumulate {
        if self.per_light {
            Accumulate::PerLight
        } else {
            Accumulate::Sum
        }
    }
}

/// How closely irradiance is computed (irradiance and falloff).
#[derive(Args, Clone, Copy)]
pub struct ToleranceArg {
    /// Relative tolerance of the irradiance, from 1e-9 to 0.1. The CPU's adaptive quadrature
    /// stops there (closed forms are exact either way); the GPU's f32 rule is fixed and held to
    /// 1e-4, so the GPU takes no tighter value (use --device cpu). `luxeval check` and the tests
    /// use the reference's 1e-9.
    #[arg(long, value_name = "REL", default_value_t = 1e-4)]
    pub tolerance: f64,
}

#[derive(Args)]
pub struct TimeArg {
    /// USD time code to evaluate at. Default: the stage's startTimeCode when authored, else each
    /// attribute's earliest time sample (USD's EarliestTime).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub time: Option<f64>,
}

/// `--device` (DESIGN.md §4).
#[derive(Clone, Copy, ValueEnum)]
pub enum DeviceArg {
    /// A hardware GPU adapter when there is one, else the CPU reference (the default).
    Auto,
    /// The GPU, software adapters (lavapipe) included; an error without one.
    Gpu,
    /// The f64 CPU reference.
    Cpu,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum FilterArg {
    Bilinear,
    Nearest,
}

impl From<FilterArg> for TextureFilter {
    fn from(f: FilterArg) -> Self {
        match f {
            FilterArg::Bilinear => TextureFilter::Bilinear,
            FilterArg::Nearest => TextureFilter::Nearest,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub enum ModeArg {
    Spec,
    Usd,
    Planckian,
}

impl From<ModeArg> for TemperatureMode {
    fn from(m: ModeArg) -> Self {
        match m {
            ModeArg::Spec => TemperatureMode::Spec,
            ModeArg::Usd => TemperatureMode::Usd,
            ModeArg::Planckian => TemperatureMode::Planckian,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub enum ScaleArg {
    Log,
    Linear,
}

pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(format!("expected three finite numbers X,Y,Z, got {s:?}")),
    }
}

pub fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let parts: Vec<&str> = s.split(',').collect();
    match parts.as_slice() {
        [w, h] => {
            let w: u32 = w.trim().parse().map_err(|e| format!("width {w:?}: {e}"))?;
            let h: u32 = h.trim().parse().map_err(|e| format!("height {h:?}: {e}"))?;
            if w == 0 || h == 0 {
                Err("width and height must be at least 1".into())
            } else {
                Ok((w, h))
            }
        }
        _ => Err(format!("expected W,H, got {s:?}")),
    }
}

pub fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [lo, hi] if lo.is_finite() && hi.is_finite() && hi > lo => Ok((*lo, *hi)),
        _ => Err(format!("expected LOW,HIGH with LOW < HIGH, got {s:?}")),
    }
}
