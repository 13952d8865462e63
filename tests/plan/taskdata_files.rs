//! TASKDATA as terminals and farm software write it (tools/fields/taskdata): byte-order marks,
//! UTF-16, partfields in external files, several partfields, types without a use here.

use agsteer::field::{
    decode_text, external_partfield_files, list_fields, load_field_with, FieldError, GuidanceKind,
    LoadOptions, LoadedField,
};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tools/fields/taskdata")
        .join(name)
}

/// The main file's text and its external partfield files, as `agsteer plan` reads them.
fn read(name: &str) -> (String, Vec<(String, String)>) {
    let d = dir(name);
    let text = decode_text(&std::fs::read(d.join("TASKDATA.XML")).unwrap()).unwrap();
    let externals = external_partfield_files(&text)
        .unwrap()
        .into_iter()
        .map(|n| {
            let body = decode_text(&std::fs::read(d.join(format!("{n}.XML"))).unwrap()).unwrap();
            (n, body)
        })
        .collect();
    (text, externals)
}

fn load(name: &str, select: Option<&str>) -> Result<LoadedField, FieldError> {
    let (text, externals) = read(name);
    load_field_with(&text, &externals, select, &LoadOptions::default())
}

#[test]
fn external_partfield_files_are_read_and_every_field_listed() {
    let (text, externals) = read("topcon_farmfacts_2021");
    assert_eq!(
        externals.iter().map(|e| e.0.as_str()).collect::<Vec<_>>(),
        ["PFD00000", "PFD00001"]
    );
    let fields = list_fields(&text, &externals).unwrap();
    assert_eq!(fields.len(), 15);
    assert_eq!(fields.iter().filter(|f| f.boundaries == 1).count(), 9);
    // Several fields and none chosen: an error naming them, not the first one silently.
    match load("topcon_farmfacts_2021", None) {
        Err(FieldError::SeveralFields { count, fields }) => {
            assert_eq!(count, 9);
            assert!(fields.contains("PFD3 \"20 Arezzo Field 2019\""), "{fields}");
        }
        other => panic!("{other:?}"),
    }
    // Chosen by id or by name (the name's case does not matter).
    let by_id = load("topcon_farmfacts_2021", Some("PFD3")).unwrap();
    let by_name = load("topcon_farmfacts_2021", Some("20 arezzo field 2019")).unwrap();
    assert_eq!(by_id.field, by_name.field);
    assert_eq!(by_id.name.as_deref(), Some("20 Arezzo Field 2019"));
    // The stated area (PFD D = 101923 m²) and the boundary's agree within 0.5 %.
    assert!((by_id.cleanup.area_before_m2 - 101_923.0).abs() < 500.0);
    match load("topcon_farmfacts_2021", Some("PFD99")) {
        Err(FieldError::NoSuchField { wanted, available }) => {
            assert_eq!(wanted, "PFD99");
            assert!(available.contains("PFD1"));
        }
        other => panic!("{other:?}"),
    }
    // A missing external file is named.
    let no_ext = load_field_with(&text, &[], Some("PFD1"), &LoadOptions::default());
    assert!(
        matches!(no_ext, Err(FieldError::NoSuchField { .. })),
        "{no_ext:?}"
    );
}

#[test]
fn guidance_patterns_are_read_as_ab_lines() {
    let f = load("topcon_farmfacts_2021", Some("PFD1")).unwrap();
    assert_eq!(f.guidance.len(), 1);
    let g = &f.guidance[0];
    assert_eq!(g.kind, GuidanceKind::AbLine);
    assert!(g.name.contains("TestTrans_AB_2"), "{}", g.name);
    // A at 45.52780540°N 9.57565580°E, B at 45.52807599°N 9.57737778°E: about 137 m at 12.6°
    // north of east.
    let len = (g.points[1] - g.points[0]).norm();
    assert!((len - 137.0).abs() < 2.0, "{len}");
    let h = g.heading().unwrap().to_degrees();
    assert!((h - 12.6).abs() < 0.5, "{h}");
    // Five AB lines on PFD5.
    let f5 = load("topcon_farmfacts_2021", Some("PFD5")).unwrap();
    assert_eq!(f5.guidance.len(), 5);
}

#[test]
fn a_byte_order_mark_and_utf16_read_like_plain_utf8() {
    let bom = std::fs::read(dir("dev4ag_partfields_bom").join("TASKDATA.XML")).unwrap();
    assert_eq!(&bom[..3], [0xEF, 0xBB, 0xBF]);
    // Even as a Rust string with the mark left in.
    let raw = String::from_utf8(bom).unwrap();
    let f = load_field_with(&raw, &[], Some("PFD12"), &LoadOptions::default()).unwrap();
    assert_eq!(
        f.field.obstacles.len(),
        1,
        "NM_Oxted_NullMeridian_Hole has a hole"
    );
    let utf16 = std::fs::read(dir("utf16_test1").join("TASKDATA.XML")).unwrap();
    assert_eq!(&utf16[..2], [0xFF, 0xFE]);
    let a = load("utf16_test1", Some("PFD2")).unwrap();
    let b = load("isoxml_js_test1", Some("PFD2")).unwrap();
    assert_eq!(a.field, b.field);
    // Big endian too.
    let text = decode_text(&utf16).unwrap();
    let mut be = vec![0xFE, 0xFF];
    be.extend(text.encode_utf16().flat_map(|u| u.to_be_bytes()));
    assert_eq!(decode_text(&be).unwrap(), text);
    assert!(matches!(
        decode_text(&[0xFF, 0xFE, 0x3C]),
        Err(FieldError::Encoding(_))
    ));
}

#[test]
fn elements_without_a_use_are_skipped_with_a_warning_naming_them() {
    let f = load("obstacle_line", None).unwrap();
    assert!(f.field.obstacles.is_empty());
    let w = f.warnings.join("\n");
    assert!(w.contains("LSG 1 of type 7 (fence) skipped"), "{w}");
    assert!(w.contains("\"ditch\": no polygon exterior"), "{w}");
    assert!(
        w.contains("type 10, headland) \"headland\": not used"),
        "{w}"
    );
    // The boundary is the same as without the extra elements.
    let plain = load("isoxml_js_test1", Some("PFD1")).unwrap();
    assert_eq!(f.field, plain.field);
}
