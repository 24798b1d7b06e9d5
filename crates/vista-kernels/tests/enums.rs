//! Every value of every built-in enum param has a meaning in its kernel's
//! CPU reference. `ParamSet::choice_in` has no default arm, so a value a
//! manifest lists but the reference does not map panics here, instead of
//! the reference silently rendering another value's image.

use vista_kernels::params::Kind;

#[test]
fn every_enum_value_has_a_meaning_in_the_cpu_reference() {
    let mut checked = Vec::new();
    for k in vista_kernels::registry().iter().filter(|k| k.has_reference()) {
        for spec in k.params() {
            let Kind::Enum(values) = &spec.kind else { continue };
            for v in values.iter() {
                let p = k
                    .resolve(None, &[(spec.name.to_string(), v.to_string())])
                    .unwrap_or_else(|e| panic!("{} {}={v}: {e}", k.name(), spec.name));
                // 2 x 2 is enough to build the reference's state and march it.
                let img = k.reference(&p, 2, 2);
                assert_eq!((img.width, img.height), (2, 2));
                checked.push(format!("{}.{}={v}", k.name(), spec.name));
            }
        }
    }
    assert!(checked.len() >= 30, "only {} enum values: {checked:?}", checked.len());
}

#[test]
#[should_panic(expected = "has no meaning in the CPU reference")]
fn a_value_the_reference_does_not_map_is_not_a_default() {
    let k = vista_kernels::find("clouds").unwrap();
    let p = k.resolve(None, &[("jitter".to_string(), "ign".to_string())]).unwrap();
    // A table that forgot "ign": choice_in refuses it instead of falling back.
    p.choice_in("jitter", &[("none", 0), ("white", 1)]);
}
