//! The penumbra decision: which receivers trace more rays from a bright shooter, decided
//! from their neighbours' pilot rays, or from their share of its power.

use super::received::Received;

/// What an element's pilot rays said.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Light {
    Full,
    Partial,
    None,
}

/// How an element's pilot rays saw the shooter; `None` when it does not receive at all.
fn light(r: &Received) -> Option<Light> {
    (r.unoccluded > 0.0).then_some(match (r.visible, r.traced) {
        (_, 0) => Light::Full,
        (v, t) if v == t => Light::Full,
        (0, _) => Light::None,
        _ => Light::Partial,
    })
}

/// Does `e` get penumbra rays? When its (edge) neighbours' pilot rays (never its own: the choice
/// must not depend on the rays it is averaged with, or it is biased) saw a penumbra: some
/// neighbour saw the shooter in part, or some saw all of it and others none.
///
/// Ward's (1991) adaptive shadow testing decides from the element's own rays and averages
/// them in; that pushes every penumbra element towards full light or full shadow (its
/// expected visibility for a true V of 0.9 is 0.95), which moved the Cornell floor's mean
/// by 1 % against a 64-ray solution. Deciding from the neighbours keeps every element's
/// estimate unbiased, and penumbrae are wider than an element, so they still find them.
pub(super) fn wants_penumbra_rays(first: &[Received], e: usize, neighbours: &[u32]) -> bool {
    if first[e].traced == 0 || first[e].unoccluded <= 0.0 {
        return false;
    }
    let (mut full, mut none) = (false, false);
    for &n in neighbours {
        match light(&first[n as usize]) {
            Some(Light::Partial) => return true,
            Some(Light::Full) => full = true,
            Some(Light::None) => none = true,
            None => {}
        }
    }
    full && none
}

/// A receiver that takes more than this share of a bright shooter's power (by its unoccluded
/// form factor) gets the penumbra rays too.
const HEAVY_SHARE: f64 = 1e-3;

/// Does `e` (of area `area`) get penumbra rays because its share of the shooter's power
/// (of area `shooter_area`) is large? Decided by geometry alone (its unoccluded form factor,
/// never its rays), so its estimate stays unbiased, as [`wants_penumbra_rays`]'s does.
///
/// A receiver beside a lamp can take a fifth of its light; with a model facet's two pilot
/// rays its visibility is 0, ½ or 1 and its error a tenth of the lamp: in Sibenik cathedral
/// one element beside the ceiling panel, its two rays both unblocked where 3 of 8 were,
/// took 6 W of the panel's 50 W more than it should, 12 % of the whole shot.
pub(super) fn heavy(first: &[Received], e: usize, area: f64, shooter_area: f64) -> bool {
    first[e].traced > 0 && area * first[e].unoccluded > HEAVY_SHARE * shooter_area
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rays(visible: u32, traced: u32) -> Received {
        Received { unoccluded: 0.1, unweighted: 0.1, visible, traced, ..Received::default() }
    }

    const DARK: Received = Received {
        unoccluded: 0.0,
        unweighted: 0.0,
        visible: 0,
        traced: 0,
        kernel_visible: 0.0,
        kernel_traced: 0.0,
    };

    /// Element 0 with neighbours 1..: penumbra rays when a neighbour saw part of the
    /// shooter, or one saw all and another none; never from its own rays alone.
    #[test]
    fn neighbours_decide_the_penumbra() {
        let ask = |own: Received, around: &[Received]| {
            let mut all = vec![own];
            all.extend_from_slice(around);
            let neighbours: Vec<u32> = (1..all.len() as u32).collect();
            wants_penumbra_rays(&all, 0, &neighbours)
        };
        assert!(ask(rays(8, 8), &[rays(8, 8), rays(3, 8)]), "a partly lit neighbour");
        assert!(ask(rays(8, 8), &[rays(8, 8), rays(0, 8)]), "lit and dark neighbours");
        assert!(ask(rays(8, 8), &[rays(0, 0), rays(0, 8)]), "no rays needed counts as lit");
        assert!(!ask(rays(4, 8), &[rays(8, 8), rays(8, 8)]), "its own penumbra is not enough");
        assert!(!ask(rays(8, 8), &[rays(0, 8), rays(0, 8)]), "all neighbours dark");
        assert!(!ask(rays(8, 8), &[DARK, rays(0, 8)]), "a neighbour that does not receive says nothing");
        assert!(!ask(rays(0, 0), &[rays(8, 8), rays(3, 8)]), "no rays of its own: nothing to refine");
        assert!(!ask(DARK, &[rays(8, 8), rays(3, 8)]), "it does not receive");
        assert!(!ask(rays(8, 8), &[]), "no neighbours");
    }

    /// A receiver taking more than a thousandth of the shooter's power gets the penumbra
    /// rays whatever its own rays saw; a light one, or one that needs no rays, does not.
    #[test]
    fn heavy_receivers_are_chosen_by_their_share_alone() {
        let all = [rays(2, 2), rays(0, 2), rays(1, 2), rays(0, 0)];
        // Unoccluded factor 0.1 on 1 m² from a 0.5 m² shooter: 20 % of its power.
        assert!(heavy(&all, 0, 1.0, 0.5) && heavy(&all, 1, 1.0, 0.5) && heavy(&all, 2, 1.0, 0.5));
        assert!(!heavy(&all, 0, 1e-3, 0.5), "0.02 % of the power");
        assert!(!heavy(&all, 3, 1.0, 0.5), "needs no rays");
    }
}
