use super::*;

#[test]
fn turns_are_planned_no_tighter_than_the_speed_allows() {
    let mut cfg = Config::default();
    // 10 km/h, 0.8 × 2 m/s²: v²/a = 4.8 m < r_min 5 m.
    assert_eq!(cfg.turn_radius(), cfg.vehicle.r_min_m);
    cfg.control.speed_kmh = 15.0;
    let v: f64 = 15.0 / 3.6;
    assert!((cfg.turn_radius() - v * v / (resolve::TURN_LATERAL_SHARE * 2.0)).abs() < 1e-12);
    assert!(cfg.coverage_params().r_min > 8.0);
    assert!(cfg.ab_params().turn.r_min > 8.0);
}

#[test]
fn defaults_are_valid() {
    assert!(Config::default().validate().is_empty());
}

#[test]
fn messages_name_key_value_and_rule() {
    let cfg = Config::parse_with(
        "[guidance]\na = 0\n[control]\ndt_s = 2\n",
        &["vehicle.wheelbase_m=-1".to_string()],
    )
    .unwrap();
    let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
    assert!(msgs.contains(&"guidance.a = 0: must be an integer >= 1".to_string()));
    assert!(msgs.contains(&"control.dt_s = 2: must be in 0.005..=0.3".to_string()));
    assert!(msgs
        .iter()
        .any(|m| m.starts_with("vehicle.wheelbase_m = -1: must be in")));
    assert!(msgs.len() >= 3, "all problems at once: {msgs:?}");
}

#[test]
fn sim_disturbance_keys_parse_and_validate() {
    let cfg = Config::parse_with(
        "[sim]\ngnss_float_windows_s = [[60.0, 20.0], [-1.0, 5.0]]\nwas_bias_deg = 12\n\
         actuator_backlash_deg = -1\nterrain_slope_deg = 25\nterrain_slope_amp_deg = 10\n",
        &[],
    )
    .unwrap();
    assert_eq!(cfg.sim.gnss_float_windows_s[0], [60.0, 20.0]);
    let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
    assert!(msgs.contains(
        &"sim.gnss_float_windows_s[1] = [-1.0, 5.0]: must be [start_s, duration_s] with \
          start_s >= 0 and duration_s > 0"
            .to_string()
    ));
    assert!(msgs.contains(&"sim.was_bias_deg = 12: must be in -10..=10".to_string()));
    assert!(msgs.contains(&"sim.actuator_backlash_deg = -1: must be in 0..=10".to_string()));
    assert!(msgs
        .iter()
        .any(|m| m.starts_with("sim.terrain_slope_amp_deg = 10: |sim.terrain_slope_deg|")));
    assert_eq!(msgs.len(), 4, "{msgs:?}");
    // The defaults are all off.
    let d = SimConfig::default();
    assert!(d.gnss_markov_sigma_m == 0.0 && d.gnss_multipath_rate_per_h == 0.0);
    assert!(d.gnss_float_windows_s.is_empty() && d.terrain_slope_deg == 0.0);
    assert!(d.imu_rate_hz == 0.0 && d.slip_mps == 0.0 && d.slip_per_roll_mps_per_deg == 0.0);
    assert!(d.was_bias_deg == 0.0);
    assert!(d.actuator_deadband_deg == 0.0 && d.actuator_backlash_deg == 0.0);
}

#[test]
fn observer_and_arcs_keys_parse_and_validate() {
    let cfg = Config::parse_with(
        "[track]\nobserver_drift_tau_s = -1\nobserver_min_speed_mps = 0\n\
         observer_offset_min_speed_mps = 20\n\
         observer_slip_limit_mps_per_deg = 2\nobserver_coast_max_s = 700\n\
         [job]\nkind = \"arcs\"\narc_sweep_deg = 360\nline_num = 0\n",
        &[],
    )
    .unwrap();
    assert_eq!(cfg.job.kind, JobKind::Arcs);
    let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
    for m in [
        "track.observer_drift_tau_s = -1: must be 0 (off) or in 1..=600",
        "track.observer_min_speed_mps = 0: must be in 0.1..=10",
        "track.observer_offset_min_speed_mps = 20: must be in 0.1..=10",
        "track.observer_slip_limit_mps_per_deg = 2: must be in 0..=1",
        "track.observer_coast_max_s = 700: must be in 0..=600",
        "job.arc_sweep_deg = 360: must be in 1..=359",
        "job.line_num = 0: must be in 1..=1000 when job.kind = \"arcs\"",
    ] {
        assert!(msgs.contains(&m.to_string()), "{m} not in {msgs:?}");
    }
    assert_eq!(msgs.len(), 7, "{msgs:?}");
    // The observer is on by default (the default tracker uses it).
    let t = TrackConfig::default();
    assert!(t.observer_bias_tau_s > 0.0 && t.observer_drift_tau_s > 0.0);
    assert!(t.observer_slip_tau_s > 0.0 && t.observer_coast_max_s > 0.0);
    assert!(Config::default().validate().is_empty());
}

#[test]
fn unknown_keys_are_rejected() {
    let err = Config::parse_with("[control]\ndt = 0.1\n", &[]).unwrap_err();
    assert!(err.to_string().contains("unknown field `dt`"), "{err}");
    let err = Config::parse_with("", &["track.nope=1".into()]).unwrap_err();
    assert!(err.to_string().contains("nope"), "{err}");
    let err = Config::parse_with("[control]\nspeed_kmn = 9\n", &[]).unwrap_err();
    assert!(
        err.to_string().contains("did you mean `speed_kmh`?"),
        "{err}"
    );
    let err = Config::parse_with("[vehicel]\n", &[]).unwrap_err();
    assert!(err.to_string().contains("did you mean `vehicle`?"), "{err}");
}

#[test]
fn overrides_parse_values_and_strings() {
    let cfg = Config::parse_with(
        "",
        &[
            "track.kind = pure_pursuit".into(),
            "job.line_num=100".into(),
            "job.point_b_m=[10.0, 20.5]".into(),
        ],
    )
    .unwrap();
    assert_eq!(cfg.track.kind, TrackerChoice::PurePursuit);
    assert_eq!(cfg.job.line_num, 100);
    assert_eq!(cfg.job.point_b_m, [10.0, 20.5]);
    assert!(matches!(
        Config::parse_with("", &["noequals".into()]),
        Err(ConfigError::BadOverride(_))
    ));
}

#[test]
fn nan_is_a_problem_not_a_panic() {
    let cfg = Config::parse_with("[control]\nspeed_kmh = nan\n", &[]).unwrap();
    let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
    assert!(msgs
        .iter()
        .any(|m| m.starts_with("control.speed_kmh = NaN")));
}

#[test]
fn job_keys_are_fixed_tuning_keys_are_not() {
    let a = Config::default();
    let tuned = Config::parse_with(
        "[track]\nld_min_m = 4.0\n[safety]\na_lat_max_m_s2 = 1.5\n",
        &[],
    )
    .unwrap();
    assert!(a.fixed_key_changes(&tuned).is_empty());
    let moved =
        Config::parse_with("[job]\nline_width_m = 4.0\n[vehicle]\nr_min_m = 6.0\n", &[]).unwrap();
    assert_eq!(a.fixed_key_changes(&moved), vec!["job", "vehicle.r_min_m"]);
    // [field] shapes the running field plan: a SIGHUP cannot change it either.
    let replanned = Config::parse_with("[field]\nheadland_passes = 1\n", &[]).unwrap();
    assert_eq!(a.fixed_key_changes(&replanned), vec!["field"]);
}

#[test]
fn field_section_parses_validates_and_builds_params() {
    let cfg = Config::parse_with(
        "[field]\nswath_angle = \"fixed\"\nswath_angle_deg = 90\nroute = \"skip\"\norigin = \"config\"\n",
        &[],
    )
    .unwrap();
    let p = cfg.coverage_params();
    assert!(
        matches!(p.swath_angle, crate::plan::coverage::SwathAngle::Fixed { angle } if (angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12)
    );
    assert_eq!(p.route, crate::plan::coverage::RouteOrder::Skip);
    assert_eq!(p.line_width, cfg.job.line_width_m);
    assert_eq!(
        cfg.field_load_options().origin.map(|o| o.lat_deg),
        Some(cfg.job.origin_lat_deg)
    );
    let bad = Config::parse_with("[field]\nboundary_tolerance_m = -1\n", &[]).unwrap();
    assert!(bad
        .validate()
        .iter()
        .any(|p| p.key == "field.boundary_tolerance_m"));
    assert!(Config::parse_with("[field]\nswath_angle = \"diagonal\"\n", &[]).is_err());
    // The overlap is checked against the job's implement: half of it or more is refused.
    let overlap = |o: &str, w: &str| {
        let cfg = Config::parse_with(
            &format!("[job]\nline_width_m = {w}\n[field]\noverlap_m = {o}\n"),
            &[],
        )
        .unwrap();
        let bad = cfg.validate().iter().any(|p| p.key == "field.overlap_m");
        (bad, cfg.coverage_params().overlap)
    };
    assert_eq!(overlap("0.1", "6"), (false, 0.1));
    assert!(overlap("3", "6").0);
    assert!(overlap("2", "3").0);
    assert!(overlap("-0.1", "6").0);
    assert!(!overlap("1.4", "3").0);
}

#[test]
fn maneuver_section_parses_validates_and_builds_params() {
    let cfg = Config::parse_with(
        "[maneuver]\ncurve = \"rs\"\nimplement_length_m = 2.0\nimplement_width_m = 3.0\n\
         goal_patterns = [\"rlr_pnp\"]\n[vehicle]\nlength_m = 5.0\n",
        &["maneuver.heading_step_deg=5".into()],
    )
    .unwrap();
    assert!(cfg.validate().is_empty(), "{:?}", cfg.validate());
    assert_eq!(cfg.maneuver.curve, CurveChoice::Rs);
    let p = cfg.maneuver_params();
    assert_eq!(p.footprint.vehicle.length_m, 5.0);
    assert_eq!(p.footprint.implement.map(|i| i.width_m), Some(3.0));
    assert!((p.heading_step_rad - 5f64.to_radians()).abs() < 1e-12);
    assert!((cfg.maneuver_curve_params().kappa_max - 1.0 / cfg.vehicle.r_min_m).abs() < 1e-12);
    let bad = Config::parse_with(
        "[maneuver]\ngoal_patterns = [\"lrx_pn\"]\nclearance_m = 0.05\nsample_tolerance_m = 0.3\n\
         max_expansions = 0\nreverse_penalty = 0.5\n[vehicle]\nrear_axle_from_rear_m = 9\n",
        &[],
    )
    .unwrap();
    let keys: Vec<String> = bad.validate().into_iter().map(|p| p.key).collect();
    for k in [
        "maneuver.goal_patterns[0]",
        "maneuver.clearance_m",
        "maneuver.max_expansions",
        "maneuver.reverse_penalty",
        "vehicle.rear_axle_from_rear_m",
    ] {
        assert!(keys.iter().any(|x| x == k), "{k} in {keys:?}");
    }
    assert!(Config::parse_with("[maneuver]\ncurve = \"dubins\"\n", &[]).is_err());
}

#[test]
fn r_min_must_be_steerable() {
    let cfg = Config::parse_with("[vehicle]\nr_min_m = 1.0\n", &[]).unwrap();
    assert!(cfg.validate().iter().any(|p| p.key == "vehicle.r_min_m"));
}

/// Every integer key of the configuration (from the default's TOML tree, not a list kept by
/// hand): (`--set` path, index within an array).
fn integer_keys() -> Vec<(String, Option<usize>)> {
    fn collect(key: &str, v: &toml::Value, keys: &mut Vec<(String, Option<usize>)>) {
        match v {
            toml::Value::Integer(_) => keys.push((key.to_string(), None)),
            toml::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    if x.is_integer() {
                        keys.push((key.to_string(), Some(i)));
                    }
                }
            }
            toml::Value::Table(t) => {
                for (k, x) in t {
                    collect(&format!("{key}.{k}"), x, keys);
                }
            }
            _ => {}
        }
    }
    let tree = toml::Table::try_from(Config::default()).unwrap();
    let mut keys = Vec::new();
    for (s, v) in &tree {
        collect(s, v, &mut keys);
    }
    keys
}

fn value_at<'a>(tree: &'a toml::Table, key: &str) -> &'a toml::Value {
    let mut parts = key.split('.');
    let mut node = tree.get(parts.next().unwrap()).unwrap();
    for p in parts {
        node = node.get(p).unwrap();
    }
    node
}

#[test]
fn every_integer_key_refuses_what_does_not_fit_and_never_wraps() {
    let keys = integer_keys();
    assert!(keys.len() >= 30, "{keys:?}");
    let tree = toml::Table::try_from(Config::default()).unwrap();
    for (key, index) in &keys {
        for v in [
            "4294967297",
            "-1",
            "256",
            "65537",
            "9223372036854775807",
            "18446744073709551617",
        ] {
            // The value at `key` (at `index` of an array, the rest as the default has it).
            let set = match index {
                None => format!("{key}={v}"),
                Some(i) => {
                    let mut arr: Vec<String> = value_at(&tree, key)
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|x| x.to_string())
                        .collect();
                    arr[*i] = v.to_string();
                    format!("{key}=[{}]", arr.join(", "))
                }
            };
            match Config::parse_with("", std::slice::from_ref(&set)) {
                // Beyond TOML's 64 bits inside an array, the whole `--set` value is a
                // string: the message then names the key and quotes the value.
                Err(ConfigError::Parse(msg)) => assert!(
                    msg.starts_with(&format!("{key} = {v}: must be an integer in "))
                        || (index.is_some() && msg.contains(key.as_str()) && msg.contains(v)),
                    "{set}: {msg}"
                ),
                Err(e) => panic!("{set}: {e}"),
                Ok(cfg) => {
                    // Accepted by the type: either a range check names the key, or the value is
                    // kept exactly as given (never wrapped or truncated).
                    if cfg
                        .validate()
                        .iter()
                        .any(|p| p.key.starts_with(key.as_str()))
                    {
                        continue;
                    }
                    let back = toml::Table::try_from(&cfg).unwrap();
                    let node = value_at(&back, key);
                    let got = match index {
                        None => node.to_string(),
                        Some(i) => node.as_array().unwrap()[*i].to_string(),
                    };
                    assert_eq!(got, v, "{set} was taken as {got}");
                }
            }
        }
    }
}

#[test]
fn tuning_that_made_tracking_unstable_is_refused_by_name() {
    // Each value below made `agsteer demo` or an accuracy scenario fail (tracking_unstable or
    // off_line) while it was in range (issue 20); the values beside it tracked.
    for (bad, good) in [
        (
            "track.observer_drift_tau_s=0.1",
            "track.observer_drift_tau_s=1",
        ),
        (
            "track.observer_bias_tau_s=0.05",
            "track.observer_bias_tau_s=0",
        ),
        ("track.tangent_length_m=0.5", "track.tangent_length_m=0.3"),
        ("track.gnss_latency_s=0.7", "track.gnss_latency_s=0.5"),
        (
            "track.integral_gain_rad_per_m_s=0.5",
            "track.integral_gain_rad_per_m_s=0.2",
        ),
        ("track.ld_min_m=12", "track.ld_min_m=6"),
        ("track.ld_gain_s=3", "track.ld_gain_s=2"),
        ("control.dt_s=0.4", "control.dt_s=0.3"),
    ] {
        let key = bad.split('=').next().unwrap();
        let problems = Config::parse_with("", &[bad.to_string()])
            .unwrap()
            .validate();
        assert!(problems.iter().any(|p| p.key == key), "{bad}: {problems:?}");
        let problems = Config::parse_with("", &[good.to_string()])
            .unwrap()
            .validate();
        assert!(
            !problems.iter().any(|p| p.key == key),
            "{good}: {problems:?}"
        );
    }
}

#[test]
fn a_lagging_steering_gets_turns_it_can_lead() {
    // A first-order lag τ follows a wheel ramp at ω a constant τ·ω behind; the tracker makes
    // that up by commanding ahead of the turn's angle, up to the supervisor's lateral
    // acceleration limit. The planned ramp leaves that lead within the margin.
    let at = |kmh: f64, tau: f64| {
        let mut cfg = Config::default();
        cfg.control.speed_kmh = kmh;
        cfg.safety.actuator_tau_s = tau;
        cfg
    };
    for (kmh, tau) in [
        (15.0, 0.6),
        (15.0, 0.15),
        (10.0, 0.15),
        (10.0, 0.4),
        (20.0, 0.3),
    ] {
        let cfg = at(kmh, tau);
        let (v, wheelbase) = (cfg.speed(), cfg.vehicle.wheelbase_m);
        let limit = (cfg.safety.a_lat_max_m_s2 * wheelbase / (v * v))
            .atan()
            .min(cfg.max_wheel_angle());
        let margin = limit - (wheelbase / cfg.turn_radius()).atan();
        // The wheel rate the turn asks for (dδ/dt ≤ L·v·σ: small angles, cos² δ ≤ 1).
        let omega = wheelbase * v * cfg.turn_curvature_rate();
        let lead = tau * omega;
        assert!(
            lead <= margin + 1e-12,
            "{kmh} km/h τ {tau}: {lead} > {margin}"
        );
        let free = at(kmh, 0.0).turn_curvature_rate();
        assert!(cfg.turn_curvature_rate() <= free);
        // No slower than it needs: the lead uses most of the margin, or the rate rules.
        assert!(
            lead >= 0.5 * margin || cfg.turn_curvature_rate() == free,
            "{kmh} km/h τ {tau}: lead {lead} of {margin}"
        );
    }
    // 0.6 s at 15 km/h: under half the rate the steering's speed alone allows.
    assert!(at(15.0, 0.6).turn_curvature_rate() < 0.5 * at(15.0, 0.0).turn_curvature_rate());
}
