//! The assumption ledger: every model parameter the workbench uses, with its value, where it
//! comes from (a source, or "inferred" and why), the scenario key that varies it in a study
//! and the range an uncertainty study gives it by default (issue 22 item 6).
//!
//! The paper's parameters are listed too, so that a reader sees in one table what is taken
//! and what is assumed. `docs/assumptions.md` holds [`ledger_markdown`] (a test keeps it
//! equal); `manifest.json` and `report.html` carry [`ledger_json`].

use serde_json::{json, Value};

/// Where a parameter's value comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// Taken from a source, named here (e.g. `USM paper Table II`).
    Paper(&'static str),
    /// Not given by any source we use; the text says how the value was chosen.
    Inferred(&'static str),
}

impl Source {
    /// Whether the value is inferred rather than taken from a source.
    pub fn is_inferred(&self) -> bool {
        matches!(self, Source::Inferred(_))
    }

    /// `source: …` or `inferred: …`, as the Markdown table shows it.
    pub fn text(&self) -> String {
        match self {
            Source::Paper(s) => (*s).to_string(),
            Source::Inferred(why) => format!("inferred: {why}"),
        }
    }
}

/// One model parameter of the ledger.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Assumption {
    /// The scenario-side key an uncertainty study or a sweep varies it with (a scale factor
    /// such as `hydro.linear_damping_scale`, or the value's own key), or `""` when no
    /// scenario key reaches it (design-side or built-in constants).
    pub key: &'static str,
    /// What the parameter is.
    pub name: &'static str,
    /// Its value, with units.
    pub value: &'static str,
    /// Where the value comes from.
    pub source: Source,
    /// The default range `(low, high)` of `key` in uncertainty studies, in the key's own
    /// units (a scale factor, an offset, m/s, deg); `None` when it is not varied by default.
    pub range: Option<(f64, f64)>,
    /// Why the range is what it is, or what else a reader should know.
    pub note: &'static str,
}

const USM_II: &str = "USM paper Table II";
const USM_VI: &str = "USM paper section VI-A";

/// The ledger, in the order of docs/model.md: vehicle and hydrodynamics, thrusters and power,
/// joints and numerics, control, scenario, the generator, then the Antonelli & Chiaverini cases.
pub const LEDGER: &[Assumption] = &[
    Assumption {
        key: "",
        name: "body masses, lengths, radius (usm-paper)",
        value: "9 bodies, 81.3 kg, 3.300 m, r = 0.085 m",
        source: Source::Paper(USM_II),
        range: None,
        note: "design-side: vary them as design axes of a study",
    },
    Assumption {
        key: "",
        name: "water density ρ",
        value: "1026 kg/m³",
        source: Source::Paper(USM_VI),
        range: None,
        note: "seawater; g = 9.81 m/s²",
    },
    Assumption {
        key: "hydro.linear_damping_scale",
        name: "linear damping, surge",
        value: "0.1 N·s/m per metre of body (0.33 N·s/m on usm-paper)",
        source: Source::Inferred(
            "the order of laminar (Blasius) skin friction 0.664ρ(νU/L)^½·2πr linearised at 0.1 m/s on the paper's hull (0.07 per m)",
        ),
        range: Some((0.0, 2.0)),
        note: "3 % of the paper design's cruise drag at 0.5 m/s (was 1 N·s/m per body, 40 %, \
               issue 22/44): from none to twice the assumption; the scale multiplies all six \
               entries",
    },
    Assumption {
        key: "hydro.linear_damping_scale",
        name: "linear damping, sway and heave",
        value: "2.7 N·s/m per metre of body",
        source: Source::Inferred(
            "the former 1 N·s/m per body of the paper's 9 bodies spread over its 3.3 m; no source: a regulariser of slow cross-flow",
        ),
        range: Some((0.0, 2.0)),
        note: "the same scale as surge",
    },
    Assumption {
        key: "hydro.linear_damping_scale",
        name: "linear damping, rotations",
        value: "0.136 N·m·s/rad per metre of body about x, y and z",
        source: Source::Inferred(
            "the former 0.05 N·m·s/rad per body of the paper's 9 bodies over its 3.3 m, so that no axis, roll included, is undamped",
        ),
        range: Some((0.0, 2.0)),
        note: "the same scale as the translations",
    },
    Assumption {
        key: "hydro.roll_damping_scale",
        name: "roll damping",
        value: "0.136 N·m·s/rad per metre of body (the rotational linear damping about x)",
        source: Source::Inferred(
            "the cross-flow strips of a cylinder make no roll moment, so this is the only roll damping",
        ),
        range: Some((0.5, 2.0)),
        note: "no source at all: a factor of 2 either way (applied on top of the linear-damping scale)",
    },
    Assumption {
        key: "hydro.drag_scale",
        name: "cross-flow drag coefficient C_d,y = C_d,z",
        value: "1.0 on 2r per unit length",
        source: Source::Paper(
            "USM paper Table II; checked: a long cylinder's subcritical C_d 1.0–1.2 at the cross-flow Re 3e3–4e4 (Hoerner 1965 ch. 3) less end effects; REMUS 100 Y_v|v| (Prestero 2001) 1.05×",
        ),
        range: Some((0.8, 1.2)),
        note: "the paper chose a typical value without experiments: ±20 %; the scale also \
               multiplies every hull-drag term below and per-body C_d,x",
    },
    Assumption {
        key: "hydro.skin_friction_scale",
        name: "hull skin friction",
        value: "ITTC-57 C_F = 0.075/(log₁₀Re − 2)² on 2πr l per body, Re = |u|L/ν of the whole chain (Re ≥ 1e5), × Hoerner's form factor 1 + 1.5(d/L)^1.5 + 7(d/L)³",
        source: Source::Paper(
            "ITTC 1957 friction line; Hoerner, Fluid-Dynamic Drag (1965) ch. 6; ν = 1.19e-6 m²/s seawater 15 °C (ITTC 7.5-02-01-03)",
        ),
        range: Some((0.8, 1.3)),
        note: "the line is for smooth turbulent flow; at Re ≈ 1e6 part of the hull is laminar \
               (less) and joints, seams and fouling roughen it (more)",
    },
    Assumption {
        key: "hydro.form_drag_scale",
        name: "nose and base drag at the chain's free ends (and diameter steps)",
        value: "C_nose 0.8, C_base 0.1 on πr² (or the exposed annulus of a step)",
        source: Source::Paper(
            "Hoerner 1965 ch. 3: flat-faced cylinder forebody ≈ 0.8 (USM Table II's end-link C_d,x); base 0.1–0.2 (C_base inferred)",
        ),
        range: Some((0.5, 1.2)),
        note: "the USM's real nose and tail are rounded to some degree (less); a flat face \
               with sharp edges is the upper end",
    },
    Assumption {
        key: "hydro.appendage_scale",
        name: "appendage allowance (thrusters, joint gaps)",
        value: "C_D·A 3.2e-3 m² per axial pod thruster, 7.7e-4 per tunnel thruster, 2.7e-4 per joint gap",
        source: Source::Inferred(
            "a 90 mm pod at C_D 0.5; a 70 mm tunnel at C_D 0.2 for its two openings; a 5 mm annular gap at C_D 0.1 on w·2πr",
        ),
        range: Some((0.5, 2.0)),
        note: "30 % of usm-paper's cruise drag at 0.5 m/s (1.59 of 5.38 N); no measurement of \
               the USM's appendages: a factor of 2 either way",
    },
    Assumption {
        key: "",
        name: "drag model",
        value: "strip theory, 5 strips per body (cross-flow); hull drag shared over the bodies (axial)",
        source: Source::Inferred(
            "the paper gives the coefficients, not how Vortex applies them (docs/model.md §2 \"Hull drag\")",
        ),
        range: None,
        note: "a design file's explicit per-body cd_x keeps USM Table II's form \
               −½ρC_d,x πr²|u|u per body; checked against NPS AUV II and REMUS 100 in \
               results/drag/",
    },
    Assumption {
        key: "hydro.lift_slope",
        name: "cross-flow lift of the chain (slender-body, at the free trailing face)",
        value: "C_Lα = 0 (off); 2 /rad on πr² when on",
        source: Source::Paper(
            "slender-body theory (Munk 1924); potential term (S_b/S) sin 2α cos(α/2) of Jorgensen, NASA TR R-474 (1977): C_Lα = 2 on the base area",
        ),
        range: Some((0.0, 2.0)),
        note: "off by default: the source is for one blunt-based body, and how far a jointed \
               chain with thrusters and gaps separates like one is not known; 2 is the \
               theory's value, 0 no lift (results/paper/FINDINGS.md §1 shows both); \
               `hydro.lift_every_body = true` puts it at every body's trailing face, an upper \
               bound",
    },
    Assumption {
        key: "hydro.added_mass_scale",
        name: "added mass, lateral and rotational",
        value: "M_A22 = M_A33 = πρr²l, M_A55 = M_A66 = πρr²l³/12, M_A44 = 0",
        source: Source::Paper(USM_VI),
        range: Some((0.9, 1.1)),
        note: "slender-body formulas for a cylinder with flat ends: ±10 %",
    },
    Assumption {
        key: "hydro.added_mass_scale",
        name: "added mass, axial ratio",
        value: "M_A11 = 0.1 m",
        source: Source::Paper(USM_VI),
        range: Some((0.9, 1.1)),
        note: "the same scale as the other entries",
    },
    Assumption {
        key: "hydro.buoyancy_offset",
        name: "buoyancy",
        value: "neutral: displaced volume m/ρ per body (generated designs: `generator.wet_weight` = 0)",
        source: Source::Paper("USM paper Table II (wet mass 0) and section VI-A"),
        range: Some((-0.02, 0.02)),
        note: "displaced volume × (1 + offset): a vehicle trimmed to within ±2 % of neutral \
               (±16 N on the 81.3 kg paper design)",
    },
    Assumption {
        key: "hydro.cb_offset_z",
        name: "metacentric height GM (CB above CG, every body)",
        value: "usm-paper: 0 (CB = CG at the volumetric centre); generated designs: 0.02 m \
                (`generator.metacentric_height`, the CB raised above the CG on the axis)",
        source: Source::Inferred(
            "the USM paper states none (CB = CG read from \"wet mass 0\"); the generator takes the \
             REMUS 100's CG 2 cm below its CB (Fossen's MSS remus100.m r_bg = [0 0 0.02] m, after \
             Prestero 2001: 1.96 cm), a 0.19 m torpedo AUV against the USM's 0.17 m",
        ),
        range: Some((-0.01, 0.01)),
        note: "every body's CB moved along its z by the offset: ballast placement known to about \
               half the REMUS value; GM 1–3 cm on generated designs, ±1 cm (top- to bottom-heavy) \
               on usm-paper; |offset| ≤ the body radius",
    },
    Assumption {
        key: "hydro.cb_offset_x",
        name: "longitudinal CB − CG offset (trim, every body)",
        value: "0: CB straight above CG in every body, the vehicle level (no trim moment)",
        source: Source::Inferred("a design is ballasted to trim level; the paper states nothing"),
        range: Some((-0.002, 0.002)),
        note: "every body's CB moved along its x: a pitch moment B·offset at level (±1.6 N·m on the \
               paper design), a trim pitch of up to asin(0.002/0.02) ≈ 5.7° at GM 2 cm: trimmed \
               to a few degrees",
    },
    Assumption {
        key: "hydro.controller_nominal",
        name: "the controller's model of the plant",
        value: "false: the base control's M_11 and n (USM-33/35) are the plant's own",
        source: Source::Inferred(
            "the paper's controller cancels its model's terms; which model it has is not stated",
        ),
        range: None,
        note: "true keeps M_11 and n at the nominal design (no world scales or CB shifts, still \
               water, payload neutral) while the plant takes the world: proposed for studies \
               with worlds",
    },
    Assumption {
        key: "thrusters.limit_scale",
        name: "thrust limits",
        value: "±40 N per thruster",
        source: Source::Paper(USM_VI),
        range: Some((0.8, 1.0)),
        note: "derating only (supply sag, wear, thruster–hull interaction lower the thrust, \
               never raise it): down to 80 %",
    },
    Assumption {
        key: "",
        name: "thruster layout (usm-paper)",
        value: "7 thrusters on L1, L2, L3 (docs/model.md §2)",
        source: Source::Inferred(
            "the paper shows the placement only in its Fig. 7; taken from NTNU theses' MATLAB code of the same Vortex model",
        ),
        range: None,
        note: "design-side: the generator's rules and thruster axes of a study vary it",
    },
    Assumption {
        key: "",
        name: "thruster response",
        value: "ideal (thrust = command)",
        source: Source::Paper("USM paper section VI-A (Vortex maps RPM to thrust statically)"),
        range: None,
        note: "`[thrusters] model = \"lag\"` or `\"rate\"` adds first-order lag or rate limits",
    },
    Assumption {
        key: "metrics.efficiency",
        name: "thruster efficiency η (shaft power = ideal power / η)",
        value: "0.5",
        source: Source::Inferred("the paper gives no propulsion data"),
        range: Some((0.4, 0.6)),
        note: "overall motor-and-propeller efficiency of small ROV thrusters: ±0.1",
    },
    Assumption {
        key: "metrics.joint_efficiency",
        name: "joint drive efficiency η_j (electrical energy = joint work / η_j)",
        value: "0.7",
        source: Source::Inferred("the paper gives no joint-drive data"),
        range: Some((0.5, 0.9)),
        note: "brushless motor with a harmonic or planetary gear; enters `total_energy` only",
    },
    Assumption {
        key: "metrics.propeller_diameter",
        name: "propeller diameter",
        value: "0.07 m",
        source: Source::Inferred("the paper gives no propulsion data; typical of small ROV thrusters"),
        range: None,
        note: "not varied by default: at zero inflow the power goes as 1/(η·D), so the \
               efficiency range already spans ±20 % of it",
    },
    Assumption {
        key: "servo.omega_n",
        name: "joint servo natural frequency ω_n",
        value: "5 rad/s",
        source: Source::Inferred(
            "Vortex sets the joint angles directly; a fast second-order filter stands for that",
        ),
        range: None,
        note: "a numerical stand-in for ideal joints rather than a hardware figure",
    },
    Assumption {
        key: "servo.zeta",
        name: "joint servo damping ratio ζ",
        value: "1 (critically damped)",
        source: Source::Inferred("as ω_n: no overshoot of the joint references"),
        range: None,
        note: "",
    },
    Assumption {
        key: "physics.rtol",
        name: "integrator tolerances",
        value: "Dormand–Prince 5(4), rtol 1e-7, atol 1e-8 (RK4: dt = 10 ms)",
        source: Source::Inferred("numerical, not physical: tight enough that results do not move"),
        range: None,
        note: "`physics.atol` and `physics.integrator` likewise",
    },
    Assumption {
        key: "scenario.control_dt",
        name: "control and logging rates",
        value: "control 20 Hz (0.05 s), logging 10 Hz",
        source: Source::Inferred("the paper does not state its control period"),
        range: None,
        note: "",
    },
    Assumption {
        key: "base_control.kp",
        name: "base control gain K_p",
        value: "diag(1, 1, 1, 0, 1, 1), no integral",
        source: Source::Paper("USM paper section VI-C"),
        range: None,
        note: "transport uses it on the axes it does not command (a reading: docs/model.md §5)",
    },
    Assumption {
        key: "base_control.nonlinear",
        name: "base control without the nonlinear term n",
        value: "τ_c = M_11 a^b (nonlinear = false)",
        source: Source::Inferred(
            "a reading of USM-33, as in the paper's own work-mode simulation; `usm-study paper readings` compares the literal form",
        ),
        range: None,
        note: "",
    },
    Assumption {
        key: "base_control.feedforward_time_constant",
        name: "base control V̇_r feed-forward filter",
        value: "0.1 s",
        source: Source::Inferred("the paper differentiates V_r without saying how"),
        range: None,
        note: "",
    },
    Assumption {
        key: "control.method",
        name: "transport gains (u0, Δ, k_ψ, k_1p, k_1I, k_6p, k_6d)",
        value: "USM Table III, Methods 1 and 2",
        source: Source::Paper("USM paper Table III"),
        range: None,
        note: "the joint sign s_q = −1 is a reading (docs/model.md §5)",
    },
    Assumption {
        key: "allocation.method",
        name: "transport allocation",
        value: "constrained QP with wrench slack, Q = 10⁴ I",
        source: Source::Inferred(
            "the paper allocates with a damped pseudoinverse (λ = 0.1, kept in work mode); the QP respects the ±40 N limits",
        ),
        range: None,
        note: "`method = \"pinv\"` gives the paper's allocator",
    },
    Assumption {
        key: "physics.current_speed",
        name: "current speed",
        value: "0 m/s",
        source: Source::Inferred("the paper's simulations state no current"),
        range: Some((0.0, 0.2)),
        note: "up to 40 % of the 0.5 m/s cruise speed: the calm end of subsea sites",
    },
    Assumption {
        key: "physics.current_direction",
        name: "current direction (from the inertial X axis)",
        value: "0 deg",
        source: Source::Inferred("as the current speed"),
        range: Some((0.0, 360.0)),
        note: "any direction",
    },
    Assumption {
        key: "physics.current_vertical",
        name: "vertical current (inertial +z, up)",
        value: "0 m/s",
        source: Source::Inferred("the paper's simulations state no current"),
        range: Some((-0.02, 0.02)),
        note: "open-ocean upwelling is of 10⁻⁴ m/s, but internal waves and flow around subsea \
               structures reach cm/s: ±2 cm/s, a tenth of the horizontal range; |w| ≤ 1 m/s is \
               refused beyond",
    },
    Assumption {
        key: "mission.payload_wet_weight",
        name: "payload wet weight m_p g − ρ V_p g",
        value: "0 N (a payload is neutral unless `payload_volume` says otherwise)",
        source: Source::Inferred("the paper carries no payload"),
        range: Some((-2.0, 2.0)),
        note: "a payload trimmed to within ±0.2 kg of neutral; only with a `mission.payload_mass` \
               of at least W/g (a wet weight above the payload's weight is refused)",
    },
    Assumption {
        key: "initial.position[1]",
        name: "transport start: lateral offset",
        value: "−3 m (3 m to the right of the first segment)",
        source: Source::Inferred("the paper's figures show the start only roughly; chosen so convergence is visible"),
        range: Some((-4.0, -2.0)),
        note: "±1 m: the ranking must not hinge on the chosen start",
    },
    Assumption {
        key: "initial.yaw_deg",
        name: "transport start: heading",
        value: "0 deg (along the first segment)",
        source: Source::Inferred("as the lateral offset"),
        range: Some((-10.0, 10.0)),
        note: "a start heading error of up to 10°",
    },
    Assumption {
        key: "",
        name: "transport path",
        value: "segments along X, the 180° turn at t = 95 s to a segment 6 m to the left, 140 s",
        source: Source::Inferred("t = 95 s and 140 s from the paper; the 6 m lane offset inferred"),
        range: None,
        note: "`path.segments` of the scenario",
    },
    Assumption {
        key: "success.max_roll_deg",
        name: "transport success: attitude and depth bounds",
        value: "|roll| and |pitch| of the base within 30° of level, base and head within 1 m of \
                their starting depth, over the whole run (`max_pitch_deg`, `max_vertical_error` \
                likewise)",
        source: Source::Inferred(
            "the paper states no attitude or depth requirement; a capsize detector, not a \
             ride-quality bound (issue 36 item 3)",
        ),
        range: None,
        note: "a run past either bound is unsuccessful and names the axis; 0 turns a bound off",
    },
    Assumption {
        key: "control.autopilot",
        name: "transport autopilot (depth hold, roll and pitch to level)",
        value: "off; when on: k_depth_p 0.25, k_depth_i 0.02 (integral clamped at 10 m·s), \
                k_roll_p 0.25, k_roll_d 1, k_pitch_p 0.25, k_pitch_d 0; roll only while T(q) \
                can command it",
        source: Source::Inferred(
            "not in the paper (its laws are kept bit for bit with the autopilot off); gains \
             chosen, reachable by a [tune]",
        ),
        range: None,
        note: "docs/model.md §5; on a design that cannot command roll the hydrostatic restoring \
               moment is all there is",
    },
    Assumption {
        key: "metrics.threshold",
        name: "singularity threshold of the commanded σ_min",
        value: "0.05 N/N",
        source: Source::Inferred("the paper gives no number for \"near singular\""),
        range: None,
        note: "`metrics.residual_tolerance` (10⁻²) likewise",
    },
    Assumption {
        key: "",
        name: "generator: link geometry and mass",
        value: "links 0.6 m, neutrally buoyant solid cylinders (m = ρπr²l); modules 0.104 m, 6 kg",
        source: Source::Inferred(
            "module size and mass from USM Table II; the link length near the paper's 0.584–0.726 m",
        ),
        range: None,
        note: "design-side (`generator.*` keys of a design or study)",
    },
    Assumption {
        key: "",
        name: "generator: hydrostatic rules",
        value: "every body's CG at its geometric centre (on the axis) and its CB `metacentric_height` \
                (0.02 m) above; `wet_weight` (0 N) spread over the bodies by mass, so the vehicle stays level",
        source: Source::Inferred(
            "GM from the REMUS 100 (see the metacentric-height row); neutral and level as the paper's \
             \"wet mass 0\"",
        ),
        range: None,
        note: "design-side (`generator.metacentric_height`, `generator.wet_weight`); worlds vary \
               them through `hydro.cb_offset_z`, `hydro.cb_offset_x` and `hydro.buoyancy_offset`",
    },
    Assumption {
        key: "",
        name: "generator: thruster rules",
        value: "paper (fractions of the usm-paper layout on links 1, ⌊N/2⌋, N−2; the end links at 3–4 \
                links, never more than 3 per link), distributed (0.35/0.65 of each inner link), \
                ends (0.4/0.6 of the end links), longitudinal pair ±0.10 m on the middle link; \
                body profile `paper`: Table II's tail/head/middle/inner link lengths and masses \
                at any N",
        source: Source::Inferred("rules of this workbench, generalising the inferred usm-paper layout"),
        range: None,
        note: "design-side (`generator.thruster_rule`)",
    },
    Assumption {
        key: "",
        name: "uvms-planar: arm and vehicle geometry",
        value: "links 2.0 m, arm base at (2.5 m, 0); arm links 30 kg, r = 0.08 m; vehicle r = 0.5 m; \
                4 thrusters of ±500 N",
        source: Source::Inferred(
            "link length and arm base fitted to Antonelli & Chiaverini's stated end-effector pose; the rest chosen",
        ),
        range: None,
        note: "the kinematic cases 1, 1b and 2 use only the geometry",
    },
    Assumption {
        key: "",
        name: "case 3: NPS AUV II",
        value: "L = 5.3 m, m = 5454.54 kg, ρ = 1000 kg/m³, manoeuvring derivatives",
        source: Source::Paper("Healey & Lienard (1993), MSS toolbox npsauv.m"),
        range: None,
        note: "",
    },
    Assumption {
        key: "",
        name: "case 3: current",
        value: "ν_c = (0.1√2, 0.1√2, 0) m/s",
        source: Source::Paper("Antonelli & Chiaverini, third case study"),
        range: None,
        note: "",
    },
    Assumption {
        key: "",
        name: "case 3: sliding-mode gains",
        value: "Λ = 0.5 1/s; K_D ≈ 2·diag(M_RB + M_A); K_S = 10 N / 50 N·m; boundary 0.01",
        source: Source::Inferred(
            "Antonelli & Chiaverini name a sliding-mode law (their ref. [1]) but give no gains",
        ),
        range: None,
        note: "the sliding variable decays at about 2 rad/s",
    },
];

/// A Markdown table cell: pipes escaped, line breaks folded.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// A range for the table: `low – high`, or `—`.
fn range_text(r: Option<(f64, f64)>) -> String {
    match r {
        Some((lo, hi)) => format!("{lo} – {hi}"),
        None => "—".to_string(),
    }
}

/// The ledger as a Markdown table (one row per [`Assumption`], in [`LEDGER`] order), ending
/// with a newline.
pub fn ledger_markdown() -> String {
    let mut out = String::from(
        "| key | parameter | value | source | uncertainty range | note |\n\
         |---|---|---|---|---|---|\n",
    );
    for a in LEDGER {
        let key = if a.key.is_empty() {
            "—".to_string()
        } else {
            format!("`{}`", a.key)
        };
        out.push_str(&format!(
            "| {key} | {} | {} | {} | {} | {} |\n",
            cell(a.name),
            cell(a.value),
            cell(&a.source.text()),
            range_text(a.range),
            cell(a.note)
        ));
    }
    out
}

/// The ledger as JSON: an array of `{key, name, value, source: {kind, text}, inferred, range,
/// note}` (`kind` is `paper` or `inferred`, `range` `[low, high]` or null), in [`LEDGER`] order.
pub fn ledger_json() -> Value {
    Value::Array(
        LEDGER
            .iter()
            .map(|a| {
                let (kind, text) = match a.source {
                    Source::Paper(s) => ("paper", s),
                    Source::Inferred(s) => ("inferred", s),
                };
                json!({
                    "key": a.key,
                    "name": a.name,
                    "value": a.value,
                    "source": { "kind": kind, "text": text },
                    "inferred": a.source.is_inferred(),
                    "range": a.range.map(|(lo, hi)| vec![lo, hi]),
                    "note": a.note,
                })
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_range_is_ordered_and_finite_and_belongs_to_a_key() {
        for a in LEDGER {
            if let Some((lo, hi)) = a.range {
                assert!(lo.is_finite() && hi.is_finite() && lo < hi, "{}", a.name);
                assert!(!a.key.is_empty(), "{}: a range needs a key", a.name);
                assert!(!a.note.is_empty(), "{}: a range needs its reason", a.name);
            }
            assert!(!a.name.is_empty() && !a.value.is_empty());
        }
    }

    #[test]
    fn the_inferred_headline_parameters_are_listed_as_inferred() {
        fn find(key: &str) -> impl Iterator<Item = &'static Assumption> + '_ {
            LEDGER.iter().filter(move |a| a.key == key)
        }
        for key in [
            "hydro.linear_damping_scale",
            "hydro.roll_damping_scale",
            "metrics.efficiency",
            "metrics.propeller_diameter",
            "servo.omega_n",
        ] {
            assert!(find(key).count() > 0, "{key} missing");
            assert!(find(key).all(|a| a.source.is_inferred()), "{key}");
        }
        assert_eq!(
            find("hydro.linear_damping_scale").next().unwrap().range,
            Some((0.0, 2.0))
        );
        assert!(find("hydro.drag_scale").all(|a| !a.source.is_inferred()));
    }

    #[test]
    fn markdown_has_one_row_per_entry_and_json_the_same_entries() {
        let md = ledger_markdown();
        assert_eq!(md.lines().count(), LEDGER.len() + 2);
        assert!(md.contains(
            "| `hydro.roll_damping_scale` | roll damping | 0.136 N·m·s/rad per metre of body (the rotational linear damping about x) | inferred: "
        ));
        for line in md.lines() {
            // Six cells on every line: escaped pipes do not split cells.
            assert_eq!(line.replace(r"\|", "").matches('|').count(), 7, "{line}");
        }
        assert!(md.contains(r"πr²\|u\|u"));
        let j = ledger_json();
        let rows = j.as_array().unwrap();
        assert_eq!(rows.len(), LEDGER.len());
        let roll = rows
            .iter()
            .find(|r| r["key"] == "hydro.roll_damping_scale")
            .unwrap();
        assert_eq!(roll["source"]["kind"], "inferred");
        assert_eq!(roll["range"], json!([0.5, 2.0]));
        assert!(rows.iter().any(|r| r["range"].is_null()));
    }
}
