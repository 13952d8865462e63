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

/// A CNH terminal's export (Another-single-ACP, ISOXML 4.2): each hole written as a boundary
/// PLN of its own holding only an interior LSG, impassable areas as obstacle PLNs whose ring is
/// a closed obstacle LSG (type 9), impassable lines directly under the partfield, and two
/// fields of the same name.
#[test]
fn holes_and_impassable_areas_as_a_cnh_terminal_writes_them() {
    // PFD-3: the exterior and three holes, each in a PLN of its own. The file states
    // 257 151 m² (PFD D), the area less the holes; the exterior alone is 279 465 m².
    let f = load("cnh_acp_2021", Some("PFD-3")).unwrap();
    assert_eq!(f.field.obstacles.len(), 3, "{:?}", f.warnings);
    assert!(
        (f.cleanup.area_before_m2 - 257_151.0).abs() < 0.005 * 257_151.0,
        "{}",
        f.cleanup.area_before_m2
    );
    let w = f.warnings.join("\n");
    assert_eq!(w.matches("taken as a hole of PLN-5").count(), 3, "{w}");
    // PFD-6: two holes so and an impassable area (PLN-20, type 6 with a closed type 9 ring);
    // the impassable line under the partfield (LSG-1, open) is named and skipped.
    let f6 = load("cnh_acp_2021", Some("PFD-6")).unwrap();
    assert_eq!(f6.field.obstacles.len(), 3, "{:?}", f6.warnings);
    let w6 = f6.warnings.join("\n");
    assert!(
        w6.contains("LSG-1 \"Impassable_Line_181018_1\": type 9 (obstacle) is a line"),
        "{w6}"
    );
    // PFD-1: a small closed obstacle ring (a triangle of about a metre) is kept.
    let f1 = load("cnh_acp_2021", Some("PFD-1")).unwrap();
    assert_eq!(f1.field.obstacles.len(), 1, "{:?}", f1.warnings);
    // The list counts them.
    let (text, externals) = read("cnh_acp_2021");
    let fields = list_fields(&text, &externals).unwrap();
    let pfd6 = fields.iter().find(|f| f.id == "PFD-6").unwrap();
    assert_eq!((pfd6.boundaries, pfd6.obstacles), (1, 1));
    // A name two fields share chooses neither.
    match load("cnh_acp_2021", Some("25.77ha with holes")) {
        Err(FieldError::AmbiguousName { fields, .. }) => {
            assert!(
                fields.contains("PFD-3") && fields.contains("PFD-5"),
                "{fields}"
            );
        }
        other => panic!("{other:?}"),
    }
}

/// The plan of a field whose holes were written as PLNs of their own keeps off them (before,
/// the holes were dropped and 7 % of the plan's points lay in them).
#[test]
fn a_plan_keeps_off_holes_written_as_plns_of_their_own() {
    use agsteer::plan::coverage::{metrics::checks::check_plan, plan_field};
    let f = load("cnh_acp_2021", Some("PFD-3")).unwrap();
    let mut p = agsteer::config::Config::default().coverage_params();
    p.line_width = 12.0;
    p.r_min = 6.0;
    let plan = plan_field(&f.field, &p).unwrap();
    assert!(plan.swaths > 0);
    let violations = check_plan(&f.field, &plan, p.line_width, p.r_min);
    assert!(violations.is_empty(), "{violations:?}");
    let in_holes = plan
        .segments
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|q| {
            f.field
                .obstacles
                .iter()
                .any(|o| agsteer::geo::polygon::contains_point(o, q))
        })
        .count();
    assert_eq!(in_holes, 0);
}

/// ISOXML version 3: the guidance line is an LSG of type 5 directly under the partfield (no
/// GGP/GPN); two points are an AB line.
#[test]
fn version_3_guidance_lines_under_the_partfield_are_read() {
    let f = load("geobird_v3", None).unwrap();
    assert_eq!(f.guidance.len(), 1);
    let g = &f.guidance[0];
    assert_eq!(g.kind, GuidanceKind::AbLine);
    assert!(g.name.contains("Set_31024_test3"), "{}", g.name);
    // A at 48.127180264°N 15.153593736°E, B at 48.127243635°N 15.148999665°E: about 341 m
    // running west, 1.2° north of west.
    let len = (g.points[1] - g.points[0]).norm();
    assert!((len - 341.0).abs() < 3.0, "{len}");
    let h = g.heading().unwrap().to_degrees();
    assert!((h - 178.8).abs() < 0.5, "{h}");
}

/// A file without a partfield that has a boundary, and a chosen partfield without one: errors
/// that say which.
#[test]
fn missing_boundaries_are_named() {
    let none = r#"<ISO11783_TaskData VersionMajor="4"><CTR A="CTR1"/></ISO11783_TaskData>"#;
    match load_field_with(none, &[], None, &LoadOptions::default()) {
        Err(e @ FieldError::NoPartfield { partfields: 0 }) => {
            assert!(
                e.to_string().contains("no partfield with a boundary"),
                "{e}"
            )
        }
        other => panic!("{other:?}"),
    }
    let bare = r#"<ISO11783_TaskData VersionMajor="4"><PFD A="PFD7" C="North" D="0"/></ISO11783_TaskData>"#;
    match load_field_with(bare, &[], Some("PFD7"), &LoadOptions::default()) {
        Err(e @ FieldError::PartfieldWithoutBoundary { .. }) => {
            assert!(
                e.to_string()
                    .starts_with("PFD7 \"North\": no field boundary"),
                "{e}"
            )
        }
        other => panic!("{other:?}"),
    }
}
