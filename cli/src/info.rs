//! `luxeval info`: the adapters, the one luxeval uses, and its limits.

use luxeval::{AdapterSummary, Evaluator};

use crate::exit::CliResult;

pub fn run(json: bool) -> CliResult {
    let adapters = luxeval::adapters();
    // What `--device auto` (the default) picks and why; then the adapter `--device gpu` opens.
    let auto = Evaluator::auto().map(|(_, why)| why);
    let chosen = Evaluator::gpu();
    if json {
        let v = serde_json::json!({
            "version": env!("CARGO_PKG_VERSION"),
            "adapters": adapters.iter().map(|a| serde_json::json!({
                "name": a.name, "backend": a.backend, "device_type": a.device_type, "driver": a.driver,
            })).collect::<Vec<_>>(),
            "auto": match &auto {
                Ok(why) => serde_json::json!({ "chosen": why }),
                Err(e) => serde_json::json!({ "error": e.to_string() }),
            },
            "chosen": match &chosen {
                Ok(g) => {
                    let adapter = g.adapter().unwrap_or_else(unknown_adapter);
                    let limits = g.device_limits();
                    serde_json::json!({
                        "name": adapter.name,
                        "backend": adapter.backend,
                        "limits": limits.as_ref().map(|l| serde_json::json!({
                            "max_storage_buffer_binding_size": l.max_storage_buffer_binding_size,
                            "max_buffer_size": l.max_buffer_size,
                            "max_compute_workgroups_per_dimension": l.max_compute_workgroups_per_dimension,
                            "max_compute_invocations_per_workgroup": l.max_compute_invocations_per_workgroup,
                        })),
                        "samples_per_dispatch_one_light": limits.as_ref().map(|l| l.samples_per_dispatch_one_light),
                        "pipeline_cache": g.pipeline_cache(),
                    })
                }
                Err(e) => serde_json::json!({ "error": e.to_string() }),
            },
        });
        outln!(
            "{}",
            serde_json::to_string_pretty(&v).expect("JSON of plain values")
        );
    } else {
        outln!("luxeval {}", env!("CARGO_PKG_VERSION"));
        outln!("adapters:");
        if adapters.is_empty() {
            outln!("  (none)");
        }
        for a in &adapters {
            outln!(
                "  {} [{}; {}; {}]",
                a.name,
                a.backend,
                a.device_type,
                a.driver
            );
        }
        match &auto {
            Ok(why) => outln!("--device auto (the default): {why}"),
            Err(e) => outln!("--device auto (the default): cannot open the adapter: {e}"),
        }
        match &chosen {
            Ok(g) => {
                let a = g.adapter().unwrap_or_else(unknown_adapter);
                outln!("--device gpu: {} ({})", a.name, a.backend);
                let Some(l) = g.device_limits() else {
                    return Ok(());
                };
                outln!(
                    "  max storage binding: {} bytes",
                    l.max_storage_buffer_binding_size
                );
                outln!("  max buffer:          {} bytes", l.max_buffer_size);
                outln!(
                    "  max workgroups/dim:  {}",
                    l.max_compute_workgroups_per_dimension
                );
                outln!(
                    "  samples per dispatch (one light): {}",
                    l.samples_per_dispatch_one_light
                );
                match g.pipeline_cache() {
                    Some(luxeval::CacheStatus {
                        path: Some(p),
                        loaded_bytes,
                        ..
                    }) => outln!(
                        "  pipeline cache: {} ({})",
                        p.display(),
                        if loaded_bytes > 0 {
                            format!("used: {loaded_bytes} bytes loaded")
                        } else {
                            "used: empty so far".into()
                        }
                    ),
                    Some(luxeval::CacheStatus {
                        reason: Some(r), ..
                    }) => outln!("  pipeline cache: not used: {r}"),
                    _ => {}
                }
            }
            Err(e) => {
                outln!("--device gpu: none: {e}")
            }
        }
    }
    Ok(())
}

fn unknown_adapter() -> AdapterSummary {
    AdapterSummary {
        name: "?".into(),
        backend: "?".into(),
        device_type: "?".into(),
        driver: "?".into(),
    }
}
