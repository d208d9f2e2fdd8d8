//! Every preset still loads under the scene checks, is stored counter-clockwise, and
//! round-trips through TOML.

use pushbot_world::Scene;
use pushbot_world::polygon::signed_area;

#[test]
fn every_preset_loads_and_round_trips() {
    for name in pushbot_world::scene::PRESETS {
        let s = Scene::preset(name).unwrap_or_else(|e| panic!("{e}"));
        let again = Scene::from_toml(&s.to_toml(), name).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s, again, "{name}");
        for o in &s.obstacles {
            assert!(signed_area(&o.outline) > 0.0, "{name}");
        }
        for o in &s.objects {
            assert!(signed_area(&o.outline) > 0.0, "{name}");
        }
    }
}
