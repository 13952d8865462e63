//! Fields too narrow for a swath inside the configured headland (issue 17 point 3): a farmer
//! with a wide implement on a small field first drops headland passes his turns do not need,
//! and where no swath fits even then, works the field round and round from the edge in.
//! Whatever is planned says so in the plan's warnings; a plan with no working pass at all is
//! refused by the caller with the numbers of [`super::headland::no_swath_fits`].

use super::{headland, CoverageParams, Field, FieldPlan, SegmentKind};
use crate::plan::types::PlanError;

/// Headland passes at most planned when the field is worked by headland passes alone.
const MAX_FILL_PASSES: usize = 64;

/// `plan_once` with `p`; when that plan has no swath: with the fewest headland passes the turns
/// need ([`headland::passes`] of no configured passes) if that lets swaths fit; else with as many
/// headland passes as fit in the field (each pass that no longer fits is simply absent).
pub fn plan_field(
    field: &Field,
    p: &CoverageParams,
    plan_once: impl Fn(&Field, &CoverageParams) -> Result<FieldPlan, PlanError>,
) -> Result<FieldPlan, PlanError> {
    let plan = plan_once(field, p)?;
    if plan.swaths > 0 {
        return Ok(plan);
    }
    let configured = headland::passes(p);
    let fewest = CoverageParams {
        headland_passes: 0,
        ..p.clone()
    };
    let needed = headland::passes(&fewest);
    if needed < configured {
        let mut q = plan_once(field, &fewest)?;
        if q.swaths > 0 {
            q.warnings.push(format!(
                "no swath fits inside {configured} headland passes of {:.1} m: planned with {needed}, the fewest the turns need (r_min {:.1} m)",
                p.line_width, p.r_min
            ));
            return Ok(q);
        }
    }
    // Headland passes from the edge in, as many as fit: the field's half width (its bounding
    // box's smaller half side bounds it) in passes, plus one.
    let (lo, hi) = crate::geo::polygon::bbox(field.boundary.iter())
        .unwrap_or((crate::geo::v2(0.0, 0.0), crate::geo::v2(0.0, 0.0)));
    let half_width = 0.5 * (hi - lo).x.min((hi - lo).y);
    let fill_passes =
        ((half_width / p.pass_spacing()).ceil() as usize + 1).clamp(configured, MAX_FILL_PASSES);
    let fill = CoverageParams {
        headland_passes: fill_passes,
        ..p.clone()
    };
    let mut q = plan_once(field, &fill)?;
    let rings = |f: &FieldPlan| {
        f.segments
            .iter()
            .filter(|s| s.kind == SegmentKind::Headland)
            .count()
    };
    if q.swaths == 0 && rings(&q) > rings(&plan) {
        q.warnings.push(format!(
            "no swath fits at {:.1} m and r_min {:.1} m: the field is worked by headland passes alone, from the edge in",
            p.line_width, p.r_min
        ));
        return Ok(q);
    }
    if q.swaths > 0 {
        return Ok(q);
    }
    Ok(plan)
}

/// Why no swath fits `field` at `p` ([`headland::no_swath_fits`] at its widest strip), with
/// the largest width that plans swaths found by planning, 0.5 m narrower each time from `p`'s
/// ([`largest_planned_width`]: the strip test alone is no bound, as ground the passes leave
/// can hold swaths of a width whose passes leave the strip no room); `None` when the strip
/// leaves room for one.
pub fn no_swath_reason(field: &Field, p: &CoverageParams) -> Option<headland::NoSwathFits> {
    let area = (field.boundary.clone(), field.obstacles.clone());
    let mut why = headland::no_swath_fits(super::geometry::inscribed_width(&area), p)?;
    let tries = (2.0 * p.line_width).ceil() as usize;
    why.largest_width = largest_planned_width(field, p, p.line_width - 0.5, tries);
    why.planned = true;
    Some(why)
}

/// Why no swath fits `field` at `p`, in words for the operator: [`no_swath_reason`], or else
/// the field's width at its widest against the implement and the turn diameter.
pub fn no_swath_words(field: &Field, p: &CoverageParams) -> String {
    match no_swath_reason(field, p) {
        Some(why) => why.to_string(),
        None => {
            let area = (field.boundary.clone(), field.obstacles.clone());
            let width = super::geometry::inscribed_width(&area);
            format!(
                "no swath fits the field ({width:.1} m wide at its widest, implement {:.1} m, turn diameter {:.1} m)",
                p.line_width,
                2.0 * p.r_min
            )
        }
    }
}

/// A plan without swaths worked by headland passes alone is accepted when they work at least
/// this fraction of the field (issue 17's "every plan ≥ 97 %"); below it, and for a plan with
/// no working pass at all, it is refused with the reason and the numbers: by `agsteer plan`
/// (exit 5) and by the field job of the daemon, the demo and the simulator alike.
pub const HEADLAND_ONLY_MIN_WORKED: f64 = 0.97;

/// Why `plan` is refused, if it is: no swath and no headland pass; or no swath, and the
/// headland passes work less than [`HEADLAND_ONLY_MIN_WORKED`] of the field (`worked`, when
/// the metrics are known). The reason names the field's width, the implement's, the turn
/// diameter and the largest width that fits.
pub fn refusal(
    field: &Field,
    params: &CoverageParams,
    plan: &FieldPlan,
    worked: Option<f64>,
) -> Option<String> {
    if plan.swaths > 0 {
        return None;
    }
    let passes = plan
        .segments
        .iter()
        .any(|s| s.kind == SegmentKind::Headland);
    let short = match worked {
        None if passes => return None,
        Some(f) if f >= HEADLAND_ONLY_MIN_WORKED => return None,
        Some(f) => format!(
            "; headland passes alone would work {:.1} % of it (< {:.0} %)",
            100.0 * f,
            100.0 * HEADLAND_ONLY_MIN_WORKED
        ),
        None => String::new(),
    };
    let reason = no_swath_words(field, params);
    Some(format!("{reason}{short}"))
}

/// The largest implement width at which [`super::plan_field`] plans swaths, trying `start` and
/// then 0.5 m narrower each time, at most `tries` plans; `None` when none of them has a swath.
pub fn largest_planned_width(
    field: &Field,
    p: &CoverageParams,
    start: f64,
    tries: usize,
) -> Option<f64> {
    let mut w = (start * 2.0).floor() / 2.0;
    for _ in 0..tries {
        if w < 0.5 || w <= 2.0 * p.overlap {
            return None;
        }
        let q = CoverageParams {
            line_width: w,
            ..p.clone()
        };
        if super::plan_field(field, &q).is_ok_and(|plan| plan.swaths > 0) {
            return Some(w);
        }
        w -= 0.5;
    }
    None
}

/// The parts of a field that a tractor cannot drive between inside the boundary (joined only
/// by necks narrower than twice [`super::TRANSIT_CLEARANCE_M`]), when there are several: the
/// field with its holes shrunk by that clearance, as areas, largest first.
pub fn parts(field: &Field) -> Vec<super::geometry::Area> {
    let whole = (field.boundary.clone(), field.obstacles.clone());
    let mut parts = super::geometry::offset(&[whole], -super::TRANSIT_CLEARANCE_M);
    if parts.len() > 1 {
        parts.sort_by(|a, b| super::geometry::area_m2(b).total_cmp(&super::geometry::area_m2(a)));
    }
    parts
}

/// Index of the part of `parts` nearest `q` (0 when there are none).
pub fn part_of(parts: &[super::geometry::Area], q: &crate::geo::Vec2) -> usize {
    use crate::geo::polygon::point_segment_distance;
    let distance = |area: &super::geometry::Area| {
        if super::geometry::in_area(area, q) {
            return 0.0;
        }
        let (outer, holes) = area;
        std::iter::once(outer)
            .chain(holes.iter())
            .flat_map(|r| {
                let n = r.len();
                (0..n).map(move |i| point_segment_distance(q, &r[i], &r[(i + 1) % n]))
            })
            .fold(f64::INFINITY, f64::min)
    };
    (0..parts.len())
        .min_by(|&i, &j| distance(&parts[i]).total_cmp(&distance(&parts[j])))
        .unwrap_or(0)
}

/// The warning for a part of the field dropped from the plan with its headland passes (or
/// stretches of them) and swaths.
pub fn dropped_part(part: &super::geometry::Area, passes: usize, swaths: usize) -> String {
    let ring = &part.0;
    let c = ring.iter().fold(crate::geo::v2(0.0, 0.0), |a, q| a + q) / ring.len().max(1) as f64;
    format!(
        "part of the field dropped: the part about ({:.1}, {:.1}), {:.2} ha, joins the planned part only by necks narrower than {:.1} m (no way inside the boundary): its {passes} headland pass(es) and {swaths} swath(s) are not planned; plan it as a field of its own",
        c.x,
        c.y,
        super::geometry::area_m2(part) / 1e4,
        2.0 * super::TRANSIT_CLEARANCE_M
    )
}
