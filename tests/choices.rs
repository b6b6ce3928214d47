//! Every closed set of choices that crosses between host and shader (`choice!`): its
//! shader-side decoder `from_u32` and the host's `Choice` agree, round trip.

use splitsum_shaders::choice::Choice;

/// For every variant of `T`: the code is its place in `ALL` (so codes are dense, from 0),
/// `from_u32` and `from_code` give it back, its name is unique and parses back; codes past
/// the end decode to the first variant, as the shaders read them.
fn round_trip<T: Choice + std::fmt::Debug>(from_u32: fn(u32) -> T) {
    let all = T::ALL;
    assert!(!all.is_empty());
    for (k, &c) in all.iter().enumerate() {
        assert_eq!(c.code(), k as u32, "{c:?}: codes follow ALL's order");
        assert_eq!(from_u32(c.code()), c, "{c:?}: from_u32");
        assert_eq!(T::from_code(c.code()), c, "{c:?}: from_code");
        assert_eq!(T::from_name(c.name()), Some(c), "{c:?}: from_name");
        assert_eq!(all.iter().filter(|d| d.name() == c.name()).count(), 1, "{c:?}: its name is unique");
    }
    for unknown in [all.len() as u32, all.len() as u32 + 7, u32::MAX] {
        assert_eq!(from_u32(unknown), all[0], "code {unknown}");
    }
    assert_eq!(T::from_name("no such choice"), None);
}

#[test]
fn every_choice_decodes_as_it_encodes() {
    use splitsum_shaders::brdf::microfacet::Masking;
    use splitsum_shaders::equirect::Facing;
    use splitsum_shaders::kernels::ProbeMode;
    use splitsum_shaders::prefilter::{Lobe, RoughnessMapping};
    use splitsum_shaders::shade::{DiffuseModel, FresnelForm, SpecularModel};
    use splitsum_shaders::tonemap::Tonemapper;
    round_trip(RoughnessMapping::from_u32);
    round_trip(Lobe::from_u32);
    round_trip(Masking::from_u32);
    round_trip(Facing::from_u32);
    round_trip(Tonemapper::from_u32);
    round_trip(DiffuseModel::from_u32);
    round_trip(SpecularModel::from_u32);
    round_trip(FresnelForm::from_u32);
    round_trip(ProbeMode::from_u32);
    round_trip(splitsum::Format::from_u32);
    round_trip(splitsum::BackendKind::from_u32);
    round_trip(splitsum::TableMethod::from_u32);
    round_trip(splitsum::Target::from_u32);
}
