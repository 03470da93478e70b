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
