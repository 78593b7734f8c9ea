//! Offline WGSL checks with naga (no GPU): every composed kernel, in every variant of its
//! optional parts, parses and validates, and the GPU record layouts equal their Rust twins.

use std::mem::{offset_of, size_of};

use luxeval::testkit::wgsl::{Features, IRR_GL_INNER, Kernel, Params, Record, SOURCES, compose};

fn module(kernel: Kernel, features: Features) -> naga::Module {
    let src = compose(kernel, features);
    naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| {
        panic!(
            "{} {features:?}:\n{}",
            kernel.file(),
            e.emit_to_string(&src)
        )
    })
}

#[test]
fn every_kernel_parses_and_validates() {
    for kernel in Kernel::ALL {
        for features in Features::variants(kernel) {
            let m = module(kernel, features);
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::default(),
            )
            .validate(&m)
            .unwrap_or_else(|e| {
                panic!(
                    "{} {features:?}: {}",
                    kernel.file(),
                    e.emit_to_string(&compose(kernel, features))
                )
            });
            assert!(
                m.entry_points
                    .iter()
                    .any(|e| e.name == kernel.entry_point()),
                "{} has no entry point {}",
                kernel.file(),
                kernel.entry_point()
            );
        }
    }
}

/// Each kernel has the optional parts the pipelines select ([`Features`]), and a variant drops
/// the code of a part that is off: the IES lookup and the texture lookups from emission and
/// radiance, the chart quadrature, treatAsLine and the textured latlong dome's row integral from
/// irradiance.
#[test]
fn optional_parts_are_dropped_from_the_source() {
    let lookups = Features {
        ies: true,
        texture: true,
        chart: false,
        line: false,
    };
    for k in [Kernel::Emission, Kernel::Radiance] {
        assert_eq!(Features::used_by(k), lookups, "{k:?}");
    }
    // The irradiance kernel imports the IES lookup (through shaping) and no texture lookup; its
    // TEXTURE part is the textured latlong dome's row integral.
    assert_eq!(
        Features::used_by(Kernel::Irradiance),
        Features {
            ies: true,
            texture: true,
            chart: true,
            line: true
        }
    );
    assert_eq!(Features::variants(Kernel::Irradiance).len(), 16);
    assert_eq!(Features::variants(Kernel::Emission).len(), 4);
    let calls = |k, f, call: &str| {
        compose(k, f)
            .lines()
            .filter(|l| !l.trim_start().starts_with("//") && l.contains(call))
            .count()
    };
    let none = Features::default();
    for k in [Kernel::Emission, Kernel::Radiance] {
        assert!(calls(k, Features::ALL, "ies_factor(") >= 2, "{k:?}");
        assert_eq!(
            calls(k, none, "ies_factor("),
            1,
            "{k:?}: only its definition"
        );
        assert!(calls(k, Features::ALL, "dome_lookup(") >= 2, "{k:?}");
        assert_eq!(
            calls(k, none, "dome_lookup("),
            1,
            "{k:?}: only its definition"
        );
    }
    let irr = Kernel::Irradiance;
    // The definition and, with the part, its one call.
    assert_eq!(calls(irr, Features::ALL, "chart_integral("), 2);
    assert_eq!(calls(irr, none, "chart_integral("), 1);
    assert_eq!(calls(irr, Features::ALL, "line_irradiance("), 2);
    assert_eq!(calls(irr, none, "line_irradiance("), 1);
    assert_eq!(calls(irr, Features::ALL, "latlong_irradiance("), 2);
    // The row integral's definition is in the part too: without it nothing of it is compiled.
    assert_eq!(calls(irr, none, "latlong_irradiance("), 0);
    assert_eq!(calls(irr, none, "fn cumulative("), 0);
    // The inner rule (ten shaping calls written out) is applied from one place: each call site
    // is a copy for Mesa's compiler (shaders/irradiance/line.wgsl, inner_adaptive).
    assert_eq!(calls(irr, Features::ALL, "inner_rule("), 2);
    // Line numbers are kept: a variant has as many lines as the whole.
    assert_eq!(
        compose(irr, none).lines().count(),
        compose(irr, Features::ALL).lines().count()
    );
}

/// Offsets and sizes of a WGSL struct's members as naga lays them out for storage buffers.
fn wgsl_layout(m: &naga::Module, name: &str) -> (u32, u32, Vec<(String, u32)>) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(m.to_ctx()).expect("layout");
    let (handle, ty) = m
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("{name} is not a struct")
    };
    let l = &layouter[handle];
    let align = l.alignment.round_up(1);
    (
        l.size,
        align,
        members
            .iter()
            .map(|mb| (mb.name.clone().unwrap_or_default(), mb.offset))
            .collect(),
    )
}

#[test]
fn record_layout_matches_naga() {
    let m = module(Kernel::Radiance, Features::ALL);
    let (size, align, members) = wgsl_layout(&m, "Record");
    assert_eq!(size as usize, size_of::<Record>(), "struct size");
    assert_eq!(size_of::<Record>() % align as usize, 0, "array stride");
    let rust = [
        ("to_local0", offset_of!(Record, to_local)),
        ("to_local1", offset_of!(Record, to_local) + 16),
        ("to_local2", offset_of!(Record, to_local) + 32),
        ("axis", offset_of!(Record, axis)),
        ("normal", offset_of!(Record, normal)),
        ("base", offset_of!(Record, base)),
        ("focus_tint", offset_of!(Record, focus_tint)),
        ("cone", offset_of!(Record, cone)),
        ("size", offset_of!(Record, size)),
        ("world_x", offset_of!(Record, world)),
        ("world_y", offset_of!(Record, world) + 16),
        ("world_z", offset_of!(Record, world) + 32),
        ("irr", offset_of!(Record, irr)),
        ("ies", offset_of!(Record, ies)),
        ("tex_inv0", offset_of!(Record, tex_inv)),
        ("tex_inv1", offset_of!(Record, tex_inv) + 16),
        ("tex_inv2", offset_of!(Record, tex_inv) + 32),
        ("tex", offset_of!(Record, tex)),
        ("kind", offset_of!(Record, kind)),
        ("flags", offset_of!(Record, flags)),
        ("pad0", offset_of!(Record, pad)),
        ("pad1", offset_of!(Record, pad) + 4),
        ("select", offset_of!(Record, select)),
    ];
    assert_eq!(members.len(), rust.len(), "member count: {members:?}");
    for ((wname, woff), (rname, roff)) in members.iter().zip(rust) {
        assert_eq!(wname, rname);
        assert_eq!(*woff as usize, roff, "offset of {wname}");
    }
}

#[test]
fn params_layout_matches_naga() {
    let m = module(Kernel::Emission, Features::ALL);
    let (size, _, members) = wgsl_layout(&m, "Params");
    assert_eq!(size as usize, size_of::<Params>());
    let rust = [
        ("count", offset_of!(Params, count)),
        ("light_first", offset_of!(Params, light_first)),
        ("light_end", offset_of!(Params, light_end)),
        ("per_light", offset_of!(Params, per_light)),
        ("row_stride", offset_of!(Params, row_stride)),
        ("accumulate", offset_of!(Params, accumulate)),
        ("lane_stride", offset_of!(Params, lane_stride)),
        ("light_filter", offset_of!(Params, light_filter)),
        ("seed", offset_of!(Params, seed)),
        ("per_point", offset_of!(Params, per_point)),
        ("first_point", offset_of!(Params, first_point)),
        ("select", offset_of!(Params, select)),
    ];
    assert_eq!(members.len(), rust.len(), "member count: {members:?}");
    for ((wname, woff), (rname, roff)) in members.iter().zip(rust) {
        assert_eq!((wname.as_str(), *woff as usize), (rname, roff));
    }
}

/// A WGSL error must surface as a readable diagnostic, not be swallowed: a broken module is
/// rejected by the same check the kernels pass.
#[test]
fn validation_rejects_a_type_error() {
    let src = format!(
        "{}\nfn broken() -> f32 {{ let x: f32 = 1u; return x; }}",
        compose(Kernel::Emission, Features::ALL)
    );
    assert!(naga::front::wgsl::parse_str(&src).is_err());
}

/// The irradiance kernel writes its inner Gauss–Legendre rule out node by node (a loop there
/// would spend llvmpipe's loop budget): as many nodes as `IRR_GL_INNER` says.
#[test]
fn inner_rule_is_written_out_with_every_node() {
    let src = SOURCES
        .iter()
        .find(|(name, _)| *name == "irradiance/line.wgsl")
        .unwrap()
        .1;
    let body = &src[src.find("fn inner_rule(").unwrap()..];
    let body = &body[..body.find("\n}").unwrap()];
    for k in 0..IRR_GL_INNER {
        assert!(
            body.contains(&format!("h, {k}u)")),
            "node {k} missing from inner_rule"
        );
    }
    assert_eq!(body.matches("inner_node(").count(), IRR_GL_INNER);
}

/// No kernel uses WGSL's builtin atan2 (off by ~3e-6 rad on lavapipe); math.wgsl's
/// atan2_accurate stands in for it everywhere.
#[test]
fn no_shader_uses_the_builtin_atan2() {
    for (path, src) in SOURCES {
        let code: String = src
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        assert!(
            !code.replace("atan2_accurate", "").contains("atan2"),
            "{path} uses the builtin atan2"
        );
    }
}

/// The IES lookup has no loop at all (lavapipe ends an invocation's loops after 65,535
/// iterations in total, and the irradiance quadrature looks a profile up thousands of times per
/// receiver): the binary search is written out as IES_SEARCH_STEPS steps.
#[test]
fn ies_lookup_has_no_loop() {
    let src = SOURCES
        .iter()
        .find(|(name, _)| *name == "shared/ies.wgsl")
        .unwrap()
        .1;
    let code: String = src
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    assert!(!code.contains("loop") && !code.contains("while") && !code.contains("for ("));
    let body = &code[code.find("fn find_interval(").unwrap()..];
    let body = &body[..body.find("\n}").unwrap()];
    let steps = body.matches("search_step(").count();
    assert_eq!(
        steps as u32,
        luxeval::testkit::ies_replay::SEARCH_STEPS,
        "{body}"
    );
}

/// The IES kink lists' binary search (irradiance/kinks.wgsl `kink_rank`) is written out, as
/// many steps as the packer allows a list (`KINK_SEARCH_STEPS`): a loop there would spend
/// lavapipe's budget on every line.
#[test]
fn kink_search_is_written_out_for_the_longest_list() {
    let src = SOURCES
        .iter()
        .find(|(name, _)| *name == "irradiance/kinks.wgsl")
        .unwrap()
        .1;
    let body = &src[src.find("fn kink_rank(").unwrap()..];
    let body = &body[..body.find("\n}").unwrap()];
    assert!(!body.contains("loop") && !body.contains("for ("), "{body}");
    assert_eq!(
        body.matches("lh = kink_step(").count() as u32,
        luxeval::testkit::ies_replay::KINK_SEARCH_STEPS,
        "{body}"
    );
}
