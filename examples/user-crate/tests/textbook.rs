//! The generated collision law of two masses on a line is the textbook
//! elastic collision: v1' = ((m1 − m2) v1 + 2 m2 v2)/(m1 + m2), and
//! symmetrically for v2'.

use dalembert_example_user::models::TwoMasses;
use dalembert_example_user::models::two_masses::Params;

#[test]
fn elastic_collision_on_a_line() {
    for (m1, m2, v1, v2) in [
        (1.0, 3.0, 2.0, -0.5),
        (2.5, 0.5, 1.0, 0.25),
        (1.0, 1.0, 3.0, -1.0),
    ] {
        let body = TwoMasses::new(Params { m1, m2 });
        let [u1, u2] = body.contact_collide(&[0.0, 0.0], &[v1, v2]);
        let e1 = ((m1 - m2) * v1 + 2.0 * m2 * v2) / (m1 + m2);
        let e2 = ((m2 - m1) * v2 + 2.0 * m1 * v1) / (m1 + m2);
        assert!(
            (u1 - e1).abs() < 1e-12 && (u2 - e2).abs() < 1e-12,
            "{u1} {u2} vs {e1} {e2}"
        );
        // Momentum and energy are kept.
        assert!((m1 * u1 + m2 * u2 - (m1 * v1 + m2 * v2)).abs() < 1e-12);
        assert!((m1 * u1 * u1 + m2 * u2 * u2 - (m1 * v1 * v1 + m2 * v2 * v2)).abs() < 1e-12);
    }
}

/// The same collision, simulated from the user's crate with the runtime's
/// simulator: the bodies approach, meet once at the predicted instant and
/// place, and leave with the textbook velocities.
#[test]
fn simulated_collision_on_a_line() {
    use dalembert_runtime::simulate::{Settings, Simulator, State};
    let body = TwoMasses::default();
    let start = State {
        t: 0.0,
        q: [0.0, 1.0],
        v: [2.0, -0.5],
    };
    let mut sim = Simulator::new(&body, start, Settings::default()).unwrap();
    let mut hits = Vec::new();
    sim.run(2.0, |step| {
        hits.extend(step.collision);
        true
    })
    .unwrap();
    assert_eq!(hits.len(), 1);
    let c = hits[0];
    // They close 1.0 at 2.5 per unit time.
    assert!((c.t - 0.4).abs() < 1e-12 && (c.q[0] - 0.8).abs() < 1e-12);
    let (m1, m2) = (body.params().m1, body.params().m2);
    let e1 = ((m1 - m2) * 2.0 + 2.0 * m2 * -0.5) / (m1 + m2);
    let e2 = ((m2 - m1) * -0.5 + 2.0 * m1 * 2.0) / (m1 + m2);
    assert!((c.v_plus[0] - e1).abs() < 1e-12 && (c.v_plus[1] - e2).abs() < 1e-12);
    assert_eq!(sim.state().v, c.v_plus);
}
