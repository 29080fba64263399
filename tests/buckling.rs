//! Why tall columns fall with soft contacts (issue 15): compliance buckling.
//!
//! A soft contact is an implicit spring of stiffness k = m_n·ω² per point (m_n the point's
//! normal effective mass, ω = 2π·hertz; `jostle_resolve::soft_step::softness`). Four such
//! points at ±a under a box make a rotational spring k_θ = 4·k·a² at each joint of a column.
//! A column of rigid blocks joined by rotational springs, loaded by its own weight, buckles
//! once the weight above each joint, acting at the lever arm its tilt creates (the "P-delta"
//! term), outweighs those springs: the lowest eigenvalue μ of M⁻¹(K − G) turns negative and
//! the mode grows as e^(√−μ·t). That is a property of the contacts' compliance, not of the
//! solver's convergence: the measured growth of a soft-step column matches the model.
//!
//! The tests here pin that mechanism at explicit soft-step settings (the defaults of
//! November 2026: 4 substeps, 30 Hz between boxes, 60 Hz against the ground), so they keep
//! explaining what soft contacts do whatever the resolver's defaults become.

mod common;

use common::family::{self, Variant};
use jostle::{BodyHandle, ResolverChoice, SoftStepSettings, World};
use nalgebra::{DMatrix, SymmetricEigen};

const DT: f32 = 1.0 / 60.0;
const HALF: f64 = 0.5;
const DENSITY: f64 = 1000.0;
const G: f64 = 9.81;

/// Soft-step settings with the given substeps and stiffnesses.
fn soft(substeps: u32, contact_hertz: f32, static_hertz: f32) -> SoftStepSettings {
    SoftStepSettings {
        substeps,
        contact_hertz,
        static_hertz,
        // The model's contacts are plain springs; load compensation stiffens a loaded spring
        // near its rest overlap, which the model does not describe.
        preload_rate: 0.0,
        // Nor does it describe the direct solve, which sizes a column's springs by their load
        // and solves the column exactly: Gauss-Seidel's soft step is what the model predicts.
        direct_rows: 0,
        ..SoftStepSettings::default()
    }
}

/// The family's column of `n` unit boxes (1000 kg/m³, μ 0.5, sleeping off) with `settings`,
/// and its top box. Contact frames are taken fresh every step (`frame_tolerance` 0): the
/// model's contact forces turn with the bodies.
fn column(n: u32, settings: SoftStepSettings) -> (World, BodyHandle) {
    column_with_frames(n, settings, 0.0)
}

/// [`column`] with the narrow phase's `frame_tolerance` (m).
fn column_with_frames(n: u32, settings: SoftStepSettings, frames: f32) -> (World, BodyHandle) {
    let scene = family::parse(&family::column(n, Variant::default()));
    let mut world_settings = scene.settings();
    world_settings.resolver = ResolverChoice::SoftStep(settings);
    world_settings.collide.frame_tolerance = frames;
    let world = scene.build_with(world_settings).unwrap();
    let top = world
        .bodies()
        .filter(|(_, _, b)| !b.is_fixed())
        .map(|(h, _, _)| h)
        .last()
        .unwrap();
    (world, top)
}

/// The lowest eigenvalue μ of M⁻¹(K − G) for the column as rigid blocks hinged at the
/// centres of their contact faces, with rotational springs from the soft contacts
/// (1/s²; negative means unstable, growing as e^(√−μ·t)).
///
/// - joint j (below block j) has k_θ = 4·k·a², k = m_n·ω² for a corner point, m_n its
///   normal effective mass (two boxes above the ground, one box on the ground);
/// - G is diagonal: block j's tilt lowers the weight of the n − j − ½ blocks it carries
///   (its own half included) by L·θ²/2 each;
/// - M is the blocks' kinetic energy in the tilts: m·JᵀJ + I·1, with block i's centre at
///   Σ_{j<i} L·θ_j + (L/2)·θ_i.
fn lowest_eigenvalue(n: usize, contact_hertz: f64, static_hertz: f64) -> f64 {
    let (a, l) = (HALF, 2.0 * HALF);
    let m = DENSITY * l * l * l;
    let inertia = m * (l * l + l * l) / 12.0;
    // |r × n|² / I for a corner (±a, −a, ±a) with n = y: (a² + a²) / I.
    let angular = 2.0 * a * a / inertia;
    let m_box_box = 1.0 / (2.0 / m + 2.0 * angular);
    let m_box_ground = 1.0 / (1.0 / m + angular);
    let omega = |hz: f64| std::f64::consts::TAU * hz;
    let k_joint = |mass: f64, hz: f64| 4.0 * mass * omega(hz).powi(2) * a * a;
    let mut k = DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        let kj = if j == 0 {
            k_joint(m_box_ground, static_hertz)
        } else {
            k_joint(m_box_box, contact_hertz)
        };
        k[(j, j)] += kj;
        if j > 0 {
            k[(j - 1, j - 1)] += kj;
            k[(j, j - 1)] -= kj;
            k[(j - 1, j)] -= kj;
        }
    }
    let weight = m * G;
    let gmat = DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            weight * l * ((n - 1 - j) as f64 + 0.5)
        } else {
            0.0
        }
    });
    let jac = DMatrix::from_fn(n, n, |i, j| match j.cmp(&i) {
        std::cmp::Ordering::Less => l,
        std::cmp::Ordering::Equal => l / 2.0,
        std::cmp::Ordering::Greater => 0.0,
    });
    let mass = jac.transpose() * &jac * m + DMatrix::identity(n, n) * inertia;
    // M = L·Lᵀ; the eigenvalues of M⁻¹(K − G) are those of L⁻¹(K − G)L⁻ᵀ, symmetric.
    let chol = mass.cholesky().expect("M is positive definite");
    let l_inv = chol.l().try_inverse().expect("L is invertible");
    let sym = &l_inv * (k - gmat) * l_inv.transpose();
    let sym = (&sym + sym.transpose()) * 0.5;
    SymmetricEigen::new(sym).eigenvalues.min()
}

/// Lateral distance of the top box from the column's axis after each of `seconds`.
fn top_lateral(world: &mut World, top: BodyHandle, seconds: &[f32]) -> Vec<f32> {
    let mut out = Vec::new();
    let mut t = 0.0f32;
    for &until in seconds {
        while t < until - 0.5 * DT {
            world.step(DT).unwrap();
            t += DT;
        }
        let p = world.body(top).unwrap().position;
        out.push(p.x.hypot(p.z));
    }
    out
}

#[test]
fn the_model_predicts_the_reported_critical_heights() {
    // Soft contacts at 30/60 Hz: stable at 15 boxes, unstable from 16; the 20-box column of
    // the issue is unstable; 60 Hz holds 20 but not 40, 120 Hz (8 substeps) not 40 either.
    let first_unstable = |hz: f64, shz: f64| {
        (2..80)
            .find(|&n| lowest_eigenvalue(n, hz, shz) < 0.0)
            .unwrap()
    };
    assert_eq!(first_unstable(30.0, 60.0), 16);
    assert_eq!(first_unstable(60.0, 60.0), 25);
    assert_eq!(first_unstable(120.0, 240.0), 39);
}

#[test]
fn a_soft_column_of_20_grows_at_the_rate_the_buckling_model_predicts() {
    let mu = lowest_eigenvalue(20, 30.0, 60.0);
    assert!(mu < 0.0, "the model says the column is stable: μ = {mu}");
    let predicted = (-mu).sqrt();
    let (mut world, top) = column(20, soft(4, 30.0, 60.0));
    // Past the settling transient the unstable mode dominates: log-linear growth.
    let r = top_lateral(&mut world, top, &[2.5, 5.0]);
    let measured = (r[1] / r[0]).ln() as f64 / 2.5;
    assert!(
        r[1] > r[0] && (measured - predicted).abs() < 0.1 * predicted,
        "measured growth {measured:.3}/s (offsets {r:?} m) against the model's {predicted:.3}/s"
    );
}

#[test]
fn stiffer_soft_contacts_hold_the_same_column_as_the_model_says() {
    // At 60 Hz both ways the model's lowest mode of a 20-box column is an oscillation
    // (μ > 0, period 8 s), so the offset stays bounded instead of growing e^(0.65·t). Eight
    // substeps keep 60 Hz below a quarter of the substep rate.
    assert!(lowest_eigenvalue(20, 60.0, 60.0) > 0.0);
    let (mut world, top) = column(20, soft(8, 60.0, 60.0));
    let seconds: Vec<f32> = (1..=40).map(|i| 0.5 * i as f32).collect();
    let r = top_lateral(&mut world, top, &seconds);
    let early = r[4..20].iter().copied().fold(0.0, f32::max);
    let late = r[20..].iter().copied().fold(0.0, f32::max);
    assert!(
        late < 3.0 * early.max(1e-4),
        "the 60 Hz column's offset grew from at most {early} m (2–10 s) to {late} m (10–20 s)"
    );
}

#[test]
fn held_contact_frames_keep_the_soft_column_of_20_standing() {
    // The same column as above, whose offset grows e^(0.65·t) with fresh frames, with the
    // narrow phase's default frame tolerance: contact forces that do not turn with the sway
    // have no P-delta term, and the column only sways (rapier3d's 20-column, which holds its
    // frames the same way, sways 27 mm).
    let tolerance = jostle::CollideSettings::default().frame_tolerance;
    assert!(tolerance > 0.0);
    let (mut world, top) = column_with_frames(20, soft(4, 30.0, 60.0), tolerance);
    let r = top_lateral(&mut world, top, &[5.0, 10.0, 20.0]);
    assert!(
        r.iter().all(|&x| x < 0.02),
        "offsets of the top at 5, 10 and 20 s: {r:?} m"
    );
}
