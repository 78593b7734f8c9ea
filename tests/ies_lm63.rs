//! The LM-63 reader (DESIGN.md §6 I1): every header version, labels, TILT in all three forms,
//! separators and line ends, and each malformed input with its line number.
use crate::ies_common;

use ies_common::*;
use luxeval::IesErrorKind as K;
use luxeval::{IesFormat as Format, Lm63Version as V, TiltSource};

/// §6 I1: candela used = value · m · b · (f₃ only for 1986/1991). With m = 2, b = 0.5, f₃ = 3
/// (1.1 in 2019, its file generation type): 3 for 1986/1991, 1 afterwards.
#[test]
fn every_header_version_and_the_f3_rule() {
    let cases: [(&str, V, f64, f64); 5] = [
        ("ACME LIGHTING 1986 REPORT 12", V::V1986, 3.0, 3.0),
        ("IESNA91", V::V1991, 3.0, 3.0),
        ("IESNA:LM-63-1995", V::V1995, 3.0, 1.0),
        ("IESNA:LM-63-2002", V::V2002, 3.0, 1.0),
        ("IES:LM-63-2019", V::V2019, 1.1, 1.0),
    ];
    for (first, version, f3, scale) in cases {
        let mut f = Ies::new(1, &[0.0], &[0.0, 90.0], &[10.0, 4.0]);
        f.head = vec![first.into(), "[MANUFAC] Acme".into()];
        (f.m, f.b, f.f3) = (2.0, 0.5, f3);
        let file = f.file();
        assert_eq!(file.format, Format::Lm63(version), "{first}");
        assert_eq!(file.candela_scale(), scale, "{first}");
        let p = luxeval::IesProfile::new(&file).unwrap();
        assert_eq!(p.candela, vec![10.0 * scale, 4.0 * scale], "{first}");
        // 1986 has no version line: its first line is a label.
        let want_labels = if version == V::V1986 { 2 } else { 1 };
        assert_eq!(file.labels.len(), want_labels, "{first}");
        assert_eq!(
            file.keywords,
            vec![("MANUFAC".to_string(), "Acme".to_string())]
        );
        assert_eq!((file.lamps, file.lumens_per_lamp, file.f3), (1.0, -1.0, f3));
        assert_eq!(
            (file.units, file.width, file.length, file.height),
            (2.0, 0.1, 0.2, 0.05)
        );
        assert_eq!((file.ballast_factor, file.input_watts), (0.5, 40.0));
    }
}

#[test]
fn labels_with_non_utf8_bytes_are_kept_lossily() {
    let text = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 1.0]).text();
    let body = &text[text.find("TILT=").unwrap()..];
    let mut bytes = b"IESNA:LM-63-2002\r\n[LUMINAIRE] Leuchte \xE9\xFC 3\r\n".to_vec();
    bytes.extend_from_slice(body.as_bytes());
    let f = luxeval::testkit::ies_parts::parse_any(&bytes, &no_tilt).unwrap();
    assert_eq!(
        f.keywords,
        vec![("LUMINAIRE".into(), "Leuchte \u{FFFD}\u{FFFD} 3".into())]
    );
    assert_eq!(
        f.labels,
        vec!["[LUMINAIRE] Leuchte \u{FFFD}\u{FFFD} 3".to_string()]
    );
    assert_eq!(f.candela, vec![1.0, 1.0]);
}

#[test]
fn a_file_may_begin_with_tilt() {
    let mut f = Ies::new(1, &[0.0], &[0.0, 90.0], &[5.0, 6.0]);
    f.head.clear();
    let file = f.file();
    assert_eq!(file.format, Format::Lm63(V::V1986));
    assert!(file.labels.is_empty());
    assert_eq!(file.candela, vec![5.0, 6.0]);
}

#[test]
fn crlf_lf_and_lone_cr_read_alike() {
    let mut f = Ies::new(
        1,
        &[0.0, 90.0],
        &[0.0, 45.0, 90.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
    );
    let crlf = f.file();
    f.eol = "\n";
    assert_eq!(f.file(), crlf);
    f.eol = "\r";
    assert_eq!(f.file(), crlf);
}

/// Values separated by any mix of blanks, tabs and commas, spread over any number of lines.
#[test]
fn commas_tabs_and_values_spread_over_lines() {
    let text = "IESNA:LM-63-2002\nTILT=NONE\n1,-1,\t2\n2\n\n2 2,\n2 0 0 0 1 1 0\n0,90\n,,0 \t\n45\n10\n20,30\n40\n";
    let f = parse(text);
    assert_eq!(f.candela_multiplier, 2.0);
    assert_eq!(f.vertical_angles, vec![0.0, 90.0]);
    assert_eq!(f.horizontal_angles, vec![0.0, 45.0]);
    assert_eq!(f.photometric_type, luxeval::PhotometricType::B);
    assert_eq!(f.candela, vec![10.0, 20.0, 30.0, 40.0]);
}

/// TILT=INCLUDE: geometry, count, angles, multipliers; §6 I5's clamped piecewise-linear factor.
#[test]
fn tilt_include_is_read_and_interpolated() {
    let mut f = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 1.0]);
    f.tilt = "INCLUDE".into();
    f.tilt_data = "1\r\n3\r\n0 45,\r\n90 1.0 0.8\r\n0.5".into();
    let file = f.file();
    let t = file.tilt.as_ref().unwrap();
    assert_eq!((t.source.clone(), t.geometry), (TiltSource::Include, 1));
    assert_eq!(
        (t.angles.clone(), t.factors.clone()),
        (vec![0.0, 45.0, 90.0], vec![1.0, 0.8, 0.5])
    );
    let p = luxeval::IesProfile::new(&file).unwrap();
    assert_close(p.tilt_factor(22.5), 0.9, 1e-15);
    assert_close(p.tilt_factor(60.0), 0.8 - 0.3 / 3.0, 1e-15); // 0.8 + (15/45)(0.5 − 0.8)
    assert_eq!(p.tilt_factor(-5.0), 1.0); // clamped below
    assert_eq!(p.tilt_factor(150.0), 0.5); // clamped above
    assert_eq!(p.tilt_factor(45.0), 0.8);
    // No tilt data: factor 1.
    assert_eq!(
        Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 1.0])
            .profile()
            .tilt_factor(30.0),
        1.0
    );
}

/// TILT=<file>: the same four items from the file the resolver returns, by the name written.
#[test]
fn tilt_file_is_resolved_by_name() {
    let mut f = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 1.0]);
    f.tilt = "lamp tilt.dat".into();
    let resolver = |name: &str| {
        assert_eq!(name, "lamp tilt.dat");
        Ok(b"2\n2\n0 90\n1 0.25\n".to_vec())
    };
    let file = luxeval::testkit::ies_parts::parse_any(f.text().as_bytes(), &resolver).unwrap();
    let t = file.tilt.unwrap();
    assert_eq!(t.source, TiltSource::File("lamp tilt.dat".into()));
    assert_eq!(
        (t.geometry, t.angles, t.factors),
        (2, vec![0.0, 90.0], vec![1.0, 0.25])
    );
}

/// A missing TILT file is an error on the TILT= line naming both files (through read_file).
#[test]
fn missing_tilt_file_names_both_files() {
    let dir = std::env::temp_dir().join(format!("ies-tilt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut f = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 1.0]);
    f.tilt = "gone.tlt".into();
    let path = dir.join("lamp.ies");
    std::fs::write(&path, f.text()).unwrap();
    let e = luxeval::read_ies(&path).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(e.line, Some(3));
    assert!(matches!(e.kind, K::TiltFileUnreadable { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("lamp.ies:3:") && msg.contains("gone.tlt"),
        "{msg}"
    );
}

#[test]
fn errors_inside_a_tilt_file_name_its_line() {
    let mut f = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 1.0]);
    f.tilt = "t.dat".into();
    let resolver = |_: &str| Ok(b"1\n2\n0 90\n1 0.5\n7\n".to_vec());
    let e = luxeval::testkit::ies_parts::parse_any(f.text().as_bytes(), &resolver).unwrap_err();
    assert_eq!(e.line, Some(3));
    match e.kind {
        K::InTiltFile { name, line, kind } => {
            assert_eq!((name.as_str(), line), ("t.dat", Some(5)));
            assert_eq!(*kind, K::TrailingToken("7".into()));
        }
        other => panic!("{other:?}"),
    }
}

/// A valid base file whose line numbers the malformed cases below rely on.
const BASE: [&str; 9] = [
    "IESNA:LM-63-2002",     // 1
    "[TEST] x",             // 2
    "TILT=NONE",            // 3
    "1 -1 1 3 2 1 2 0 0 0", // 4
    "1 1 50",               // 5
    "0 45 90",              // 6 vertical
    "0 90",                 // 7 horizontal
    "10 20 30",             // 8
    "40 50 60",             // 9
];

fn with_line(n: usize, content: &str) -> String {
    let mut l: Vec<String> = BASE.iter().map(|s| s.to_string()).collect();
    l[n - 1] = content.into();
    l.join("\r\n") + "\r\n"
}

#[test]
fn the_base_file_is_valid() {
    let f = parse(&(BASE.join("\r\n") + "\r\n"));
    assert_eq!(f.candela, vec![10.0, 20.0, 30.0, 40.0, 50.0, 60.0]);
}

/// Each malformed input: its error kind and the line of the offending (or missing) value.
#[test]
fn malformed_inputs_report_kind_and_line() {
    type Check = fn(&K) -> bool;
    let cases: Vec<(String, Option<usize>, Check)> = vec![
        (with_line(3, "TILT="), Some(3), |k| *k == K::EmptyTilt),
        (with_line(4, "1 -1 1 1 2 1 2 0 0 0"), Some(4), |k| {
            matches!(k, K::OutOfRange { .. })
        }),
        (with_line(4, "1 -1 1 2.5 2 1 2 0 0 0"), Some(4), |k| {
            matches!(k, K::NotAnInteger { .. })
        }),
        (with_line(4, "1 -1 1 3 2 4 2 0 0 0"), Some(4), |k| {
            *k == K::BadPhotometricType(4.0)
        }),
        (with_line(4, "1 -1 1 3 2 1.5 2 0 0 0"), Some(4), |k| {
            *k == K::BadPhotometricType(1.5)
        }),
        (with_line(5, "1 abc 50"), Some(5), |k| {
            matches!(k, K::NotANumber { .. })
        }),
        (with_line(6, "0 45 45"), Some(6), |k| {
            matches!(k, K::NotIncreasing { .. })
        }),
        (with_line(6, "0 45 190"), Some(6), |k| {
            matches!(k, K::OutOfRange { .. })
        }),
        (with_line(7, "0 45"), Some(7), |k| {
            matches!(k, K::BadCoverage { .. })
        }),
        (with_line(9, "40 -50 60"), Some(9), |k| {
            *k == K::NegativeCandela(-50.0)
        }),
        (with_line(9, "40 nan 60"), Some(9), |k| {
            matches!(k, K::NotANumber { .. })
        }),
        (with_line(9, "40 inf 60"), Some(9), |k| {
            matches!(k, K::NotANumber { .. })
        }),
        (with_line(9, "40 50"), Some(9), |k| {
            matches!(k, K::MissingValue { .. })
        }),
        (with_line(9, "40 50 60 70"), Some(9), |k| {
            *k == K::TrailingToken("70".into())
        }),
        (with_line(4, "1 -1 -1 3 2 1 2 0 0 0"), Some(4), |k| {
            matches!(k, K::OutOfRange { .. })
        }),
        (with_line(5, "-1 1 50"), Some(5), |k| {
            matches!(k, K::OutOfRange { .. })
        }),
        // Counts larger than the file: refused before any allocation.
        (
            with_line(4, "1 -1 1 3 4000000000 1 2 0 0 0"),
            Some(4),
            |k| matches!(k, K::CountTooLarge { .. }),
        ),
        (with_line(4, "1 -1 1 1e15 2 1 2 0 0 0"), Some(4), |k| {
            matches!(k, K::CountTooLarge { .. })
        }),
        // Type B angles lie in [−90, 90].
        (
            with_line(7, "0 100").replace("1 2 0 0 0", "2 2 0 0 0"),
            Some(7),
            |k| matches!(k, K::OutOfRange { .. }),
        ),
    ];
    for (text, line, check) in cases {
        let e = parse_err(&text);
        assert_eq!(e.line, line, "{e}\n{text}");
        assert!(check(&e.kind), "{e:?}\n{text}");
    }
}

/// Multipliers whose product with the values overflows f64 are refused (on the multiplier line).
#[test]
fn overflowing_multipliers_are_refused() {
    let e = parse_err(&with_line(4, "1 -1 1e300 3 2 1 2 0 0 0").replace("40 50 60", "40 50 1e10"));
    assert_eq!(
        (e.line, matches!(e.kind, K::ScaledCandela(_))),
        (Some(4), true),
        "{e}"
    );
}

#[test]
fn tilt_data_errors() {
    let tilt = |data: &str| with_line(3, &format!("TILT=INCLUDE\r\n{data}"));
    let e = parse_err(&tilt("4 1 0 1"));
    assert_eq!(
        (e.line, matches!(e.kind, K::OutOfRange { .. })),
        (Some(4), true),
        "{e}"
    );
    let e = parse_err(&tilt("1 2 0 0 1 1"));
    assert_eq!(
        (e.line, matches!(e.kind, K::NotIncreasing { .. })),
        (Some(4), true),
        "{e}"
    );
    let e = parse_err(&tilt("1 2 0 10 1 -1"));
    assert_eq!(
        (e.line, matches!(e.kind, K::OutOfRange { .. })),
        (Some(4), true),
        "{e}"
    );
    let e = parse_err(&tilt("1 99999999 0 10"));
    assert_eq!(
        (e.line, matches!(e.kind, K::CountTooLarge { .. })),
        (Some(4), true),
        "{e}"
    );
}

/// No TILT= line: parse_lm63 says so; parse_any cannot tell the format at all.
#[test]
fn no_tilt_line() {
    let text = BASE
        .iter()
        .filter(|l| !l.starts_with("TILT"))
        .cloned()
        .collect::<Vec<_>>()
        .join("\n");
    let e = luxeval::testkit::ies_parts::parse_lm63(text.as_bytes(), &no_tilt).unwrap_err();
    assert_eq!((e.line, e.kind), (None, K::NoTiltLine));
    assert_eq!(parse_err(&text).kind, K::UnknownFormat);
}

/// An empty input and a lone TILT line fail cleanly.
#[test]
fn truncated_files() {
    assert_eq!(parse_err("").kind, K::UnknownFormat);
    let e = parse_err("IESNA:LM-63-2002\nTILT=NONE\n");
    assert_eq!(
        (e.line, matches!(e.kind, K::MissingValue { .. })),
        (Some(2), true),
        "{e}"
    );
}

/// An unreadable file is an I/O error naming it, without a line.
#[test]
fn unreadable_file_names_it() {
    let path = std::env::temp_dir().join("ies-no-such-dir/none.ies");
    let e = luxeval::read_ies(&path).unwrap_err();
    assert!(matches!(e.kind, K::Io(_)) && e.line.is_none(), "{e:?}");
    assert!(e.to_string().contains("none.ies"), "{e}");
}
