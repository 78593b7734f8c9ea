//! EULUMDAT: each Isym against hand values, the lamp flux rule, content detection whatever the
//! extension, and malformed files with their line numbers.
use crate::ies_common;

use ies_common::*;
use luxeval::IesErrorKind as K;
use luxeval::IesFormat as Format;
use luxeval::IesProfile as Profile;
use luxeval::testkit::ies_parts::ies_factor;

/// An EULUMDAT file: `planes` are the stored planes (Mc1..=Mc2) in file order, cd/klm.
struct Ldt {
    isym: u8,
    c: Vec<f64>,
    gamma: Vec<f64>,
    planes: Vec<Vec<f64>>,
    sets: Vec<(f64, f64)>, // (number of lamps, total flux lm)
    conversion: String,
}

impl Ldt {
    fn new(isym: u8, c: &[f64], gamma: &[f64], planes: Vec<Vec<f64>>) -> Self {
        Ldt {
            isym,
            c: c.to_vec(),
            gamma: gamma.to_vec(),
            planes,
            sets: vec![(2.0, 2000.0)],
            conversion: "1.0".into(),
        }
    }

    fn lines(&self) -> Vec<String> {
        let mut l: Vec<String> = vec![
            "luxeval test luminaire".into(),
            "1".into(),
            self.isym.to_string(),
            self.c.len().to_string(),
            "0".into(), // Dc = 0: non-equidistant
            self.gamma.len().to_string(),
            "0".into(),
            "report 42".into(),
            "Test downlight".into(),
            "TD-1".into(),
            "td1.ldt".into(),
            "2024-05-01 / tester".into(),
        ];
        for d in [
            "600", "600", "80", "500", "500", "0", "0", "0", "0", "100", "80",
        ] {
            l.push(d.into());
        }
        l.push(self.conversion.clone());
        l.push("0".into()); // tilt during measurement
        l.push(self.sets.len().to_string());
        l.extend(self.sets.iter().map(|s| s.0.to_string()));
        l.extend(self.sets.iter().map(|_| "LED module".to_string()));
        l.extend(self.sets.iter().map(|s| s.1.to_string()));
        l.extend(self.sets.iter().map(|_| "3000 K".to_string()));
        l.extend(self.sets.iter().map(|_| "Ra 90".to_string()));
        l.extend(self.sets.iter().map(|_| "36".to_string()));
        l.extend((0..10).map(|k| format!("0.{k}")));
        l.extend(self.c.iter().map(|x| x.to_string()));
        l.extend(self.gamma.iter().map(|x| x.to_string()));
        l.extend(self.planes.iter().flatten().map(|x| x.to_string()));
        l
    }

    fn text(&self) -> String {
        self.lines().join("\r\n") + "\r\n"
    }

    fn profile(&self) -> Profile {
        let f = parse(&self.text());
        assert_eq!(f.format, Format::Eulumdat);
        Profile::new(&f).unwrap()
    }
}

/// Candela toward C-plane `c`, angle γ from nadir (C-γ = LM-63 type C).
fn at(p: &Profile, c: f64, gamma: f64) -> f64 {
    ies_factor(p, dir_c(c, gamma), 0.0)
}

const G: [f64; 3] = [0.0, 90.0, 180.0];

/// Planes of constant value `k` over γ.
fn flat(values: &[f64]) -> Vec<Vec<f64>> {
    values.iter().map(|&v| vec![v; 3]).collect()
}

// Flux 2000 lm, conversion 1: candela = cd/klm × 2.

#[test]
fn isym_1_rotational() {
    let p = Ldt::new(
        1,
        &[0.0, 90.0, 180.0, 270.0],
        &G,
        vec![vec![100.0, 50.0, 0.0]],
    )
    .profile();
    for c in [0.0, 77.0, 300.0] {
        assert_close(at(&p, c, 45.0), 150.0, 1e-12); // 75 cd/klm × 2
    }
}

#[test]
fn isym_2_symmetric_to_c0_c180() {
    let p = Ldt::new(2, &[0.0, 90.0, 180.0, 270.0], &G, flat(&[10.0, 20.0, 30.0])).profile();
    assert_close(at(&p, 270.0, 60.0), 40.0, 1e-12); // mirror of C90
    assert_close(at(&p, 225.0, 60.0), 50.0, 1e-12); // mirror of C135: (20 + 30)/2 × 2
    assert_close(at(&p, 45.0, 60.0), 30.0, 1e-12);
}

/// Isym 3 stores C270..C0..C90 (Mc1 = 3Mc/4 + 1); C and 180 − C are the same light.
#[test]
fn isym_3_symmetric_to_c90_c270() {
    let c: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
    // Stored C270, C300, C330, C0, C30, C60, C90: 10, 20, ..., 70 cd/klm.
    let p = Ldt::new(3, &c, &G, flat(&[10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0])).profile();
    assert_close(at(&p, 300.0, 60.0), 40.0, 1e-12);
    assert_close(at(&p, 240.0, 60.0), 40.0, 1e-12); // 180 − 240 = −60 ≡ 300
    assert_close(at(&p, 120.0, 60.0), 120.0, 1e-12); // ≡ C60
    assert_close(at(&p, 15.0, 60.0), 90.0, 1e-12); // between C0 (40) and C30 (50)
    assert_close(at(&p, 165.0, 60.0), 90.0, 1e-12); // ≡ C15
    assert_close(at(&p, 180.0, 60.0), 80.0, 1e-12); // ≡ C0
    assert_close(at(&p, 90.0, 60.0), 140.0, 1e-12);
    assert_close(at(&p, 270.0, 60.0), 20.0, 1e-12);
}

#[test]
fn isym_4_symmetric_to_both_planes() {
    let p = Ldt::new(4, &[0.0, 90.0, 180.0, 270.0], &G, flat(&[10.0, 30.0])).profile();
    assert_close(at(&p, 135.0, 60.0), 40.0, 1e-12); // ≡ C45: 20 × 2
    assert_close(
        at(&p, 300.0, 60.0),
        2.0 * (10.0 + 20.0 * 60.0 / 90.0),
        1e-12,
    ); // ≡ C60
}

#[test]
fn isym_0_no_symmetry_wraps_to_c0() {
    let p = Ldt::new(
        0,
        &[0.0, 90.0, 180.0, 270.0],
        &G,
        flat(&[10.0, 20.0, 30.0, 40.0]),
    )
    .profile();
    assert_close(at(&p, 315.0, 60.0), 50.0, 1e-12); // (40 + 10)/2 × 2
    assert_close(at(&p, 45.0, 60.0), 30.0, 1e-12);
    // Only C0 and C180: 180..360 interpolates back to C0 (a copy of C0 at 360 is appended).
    let p = Ldt::new(0, &[0.0, 180.0], &G, flat(&[10.0, 20.0])).profile();
    assert_eq!(p.h, vec![0.0, 180.0, 360.0]);
    assert_close(at(&p, 270.0, 60.0), 30.0, 1e-12);
    assert_close(at(&p, 90.0, 60.0), 30.0, 1e-12);
}

/// γ grid values carry through, the first lamp set's flux scales (further sets are
/// alternatives), and the conversion factor multiplies.
#[test]
fn flux_of_the_first_lamp_set_and_conversion_factor() {
    let mut l = Ldt::new(
        1,
        &[0.0],
        &[0.0, 40.0, 180.0],
        vec![vec![300.0, 100.0, 0.0]],
    );
    l.sets = vec![(1.0, 500.0), (3.0, 9000.0)];
    l.conversion = "1,5".into(); // decimal comma
    let f = parse(&l.text());
    assert_eq!(f.rated_lumens(), Some(500.0));
    assert_eq!(f.eulumdat.as_ref().unwrap().lamp_sets.len(), 2);
    let p = Profile::new(&f).unwrap();
    assert_close(at(&p, 10.0, 20.0), 200.0 * 1.5 * 0.5, 1e-12);
    // A constant 100 cd/klm over the sphere with 2000 lm: mean 200 cd, flux 800π lm.
    let p = Ldt::new(1, &[0.0], &G, flat(&[100.0])).profile();
    assert_close(p.mean_intensity(), 200.0, 1e-14);
}

/// The format is told by content: an LDT named .ies and an LM-63 file named .ldt both read.
#[test]
fn content_detection_ignores_the_extension() {
    let dir = std::env::temp_dir().join(format!("ies-detect-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ldt = Ldt::new(1, &[0.0], &G, flat(&[100.0])).text();
    let lm63 = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 2.0]).text();
    for (name, text, want) in [
        ("a.ldt", &ldt, Format::Eulumdat),
        ("a.ies", &ldt, Format::Eulumdat),
        ("a.txt", &ldt, Format::Eulumdat),
        ("b.ldt", &lm63, Format::Lm63(luxeval::Lm63Version::V2002)),
        ("b", &lm63, Format::Lm63(luxeval::Lm63Version::V2002)),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        assert_eq!(luxeval::read_ies(&path).unwrap().format, want, "{name}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Line numbers of the base file above: 1 company, 2 Ityp, 3 Isym, 4 Mc, 5 Dc, 6 Ng, 7 Dg,
/// ..., 26 number of lamp sets, 27 lamps, 28 type, 29 flux, ..., 33–42 direct ratios,
/// 43.. C angles.
#[test]
fn malformed_files_report_kind_and_line() {
    let base = Ldt::new(2, &[0.0, 90.0, 180.0, 270.0], &G, flat(&[10.0, 20.0, 30.0]));
    let set = |n: usize, v: &str| {
        let mut l = base.lines();
        l[n - 1] = v.into();
        l.join("\n") + "\n"
    };
    type Check = fn(&K) -> bool;
    let cases: Vec<(String, usize, Check)> = vec![
        (set(3, "5"), 3, |k| matches!(k, K::OutOfRange { .. })),
        (set(3, "1.5"), 3, |k| matches!(k, K::NotAnInteger { .. })),
        (set(4, "6").replace("\n2\n6\n", "\n3\n6\n"), 4, |k| {
            matches!(k, K::BadSymmetry { .. })
        }),
        (set(4, "3"), 4, |k| matches!(k, K::BadSymmetry { .. })),
        (set(6, "1"), 6, |k| matches!(k, K::OutOfRange { .. })),
        (set(26, "0"), 26, |k| *k == K::NoLampSet),
        (set(26, "999"), 26, |k| matches!(k, K::CountTooLarge { .. })),
        (set(29, "-5"), 29, |k| matches!(k, K::OutOfRange { .. })),
        (set(24, "x"), 24, |k| matches!(k, K::NotANumber { .. })),
        (set(44, "0"), 44, |k| matches!(k, K::NotIncreasing { .. })),
        (set(46, "360"), 46, |k| matches!(k, K::OutOfRange { .. })),
        (set(48, "200"), 48, |k| matches!(k, K::OutOfRange { .. })),
        (set(50, "-1"), 50, |k| *k == K::NegativeCandela(-1.0)),
        (set(58, "30 7"), 58, |k| *k == K::TrailingToken("7".into())),
        // C180 of an Isym 2 file must be at 180.
        (set(45, "170"), 43 + 3, |k| {
            matches!(k, K::BadSymmetry { .. })
        }),
    ];
    for (text, line, check) in cases {
        let e = parse_err(&text);
        assert_eq!(e.line, Some(line), "{e}");
        assert!(check(&e.kind), "{e:?}");
    }
    // Truncated: the last line is named.
    let short = base.lines()[..55].join("\n");
    let e = parse_err(&short);
    assert_eq!(
        (e.line, matches!(e.kind, K::MissingValue { .. })),
        (Some(55), true),
        "{e}"
    );
}
