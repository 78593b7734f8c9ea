//! The prepared scenes of a `Stage`, one per set of options, kept for later calls.

use std::collections::HashMap;
use std::sync::Arc;

use luxeval::PreparedScene;
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;

use super::{Key, Stage};
use crate::args::Options;
use crate::device;
use crate::errors::{self, no_panic};

impl Stage {
    /// The prepared scene for these options, from the cache or prepared now.
    pub(super) fn prepare_for(&self, py: Python<'_>, o: &Options) -> PyResult<Arc<PreparedScene>> {
        // Selection and attribute errors first: they cost nothing to find, a device does.
        let mut lights = self
            .scene
            .evaluable(&o.select)
            .map_err(|e| errors::lux(e, Some(self.file())))?;
        for l in &mut lights {
            l.validate()
                .map_err(|e| errors::lux(e, Some(self.file())))?;
            if let Some(t) = &mut l.texture {
                t.filter = o.filter;
            }
        }
        let eval = device::evaluator(py, o.device, o.mode)?.with_portal_mode(o.portal);
        let mut select = o.select.clone();
        select.sort();
        select.dedup();
        let key = Key {
            select,
            gpu: eval.is_gpu(),
            mode: o.mode,
            filter: o.filter,
            portal: o.portal,
        };
        if let Some(p) = self.cache().get(&key) {
            return Ok(p.clone());
        }
        if lights.is_empty() {
            let msg = format!(
                "{}: no light to evaluate; the result is all zeros",
                self.path.display()
            );
            errors::warn::<PyUserWarning>(py, &msg)?;
        }
        let file = self.file();
        let scene = py.detach(|| {
            no_panic(|| {
                eval.prepare(&lights)
                    .map_err(|e| errors::lux(e, Some(file)))
            })
        })?;
        let scene = Arc::new(scene);
        Ok(self.cache().entry(key).or_insert(scene).clone())
    }

    pub(super) fn cache(&self) -> std::sync::MutexGuard<'_, HashMap<Key, Arc<PreparedScene>>> {
        self.prepared
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// A `UserWarning` when `k` of a call's `rows` irradiance rows were recomputed on the CPU
    /// reference because the device could not finish them
    /// (`PreparedScene::host_recomputed_rows`; the command line's `note:` line).
    pub(super) fn warn_host_recomputed(
        &self,
        py: Python<'_>,
        k: usize,
        rows: usize,
    ) -> PyResult<()> {
        if k == 0 {
            return Ok(());
        }
        let msg = format!(
            "{}: {k} of {rows} irradiance rows were recomputed on the CPU reference: the device \
             could not finish their quadrature (more breakpoints than the kernel holds, or a \
             software GPU's loop budget)",
            self.path.display()
        );
        errors::warn::<PyUserWarning>(py, &msg)
    }
}
