//! The search over model classes by their evidence, forward and backward
//! (Kass & Raftery's "Occam's window" walked greedily): from the class of
//! highest evidence, try each class with one more registered effect; when
//! one of them has a higher evidence, move there and try each class with
//! one of its effects dropped; stop when no class within one step beats
//! the best. With k effects this tries O(k²) classes, not 2^k. No
//! threshold: the classes are compared by their log-posterior (log-evidence
//! plus log-prior, [`super::class_odds::ln_prior`]; equal priors by
//! default), so a class is kept only when its gain in fit outweighs its
//! Occam factor and its prior.

use std::collections::BTreeMap;

use super::cause::Cause;
use super::effect::EFFECTS;

/// Log-posterior (unnormalised) of each class tried (None: tried, but no
/// evidence had).
pub type Tried = BTreeMap<Cause, Option<f64>>;

/// The class of highest posterior among those tried (None: none has one).
pub fn best_class(tried: &Tried) -> Option<Cause> {
    tried
        .iter()
        .filter_map(|(c, z)| z.filter(|z| z.is_finite()).map(|z| (*c, z)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(c, _)| c)
}

/// Extends `tried` by the forward–backward search: `in_place` says which
/// classes the specimen admits, `try_class` calibrates one class and
/// returns its log-posterior. Returns the classes it tried, in order.
pub fn search_classes<E>(
    tried: &mut Tried,
    in_place: &dyn Fn(Cause) -> bool,
    try_class: &mut dyn FnMut(Cause) -> Result<Option<f64>, E>,
) -> Result<Vec<Cause>, E> {
    let mut order = Vec::new();
    let mut attempt = |c: Cause, tried: &mut Tried| -> Result<(), E> {
        if in_place(c) && !tried.contains_key(&c) {
            let z = try_class(c)?;
            tried.insert(c, z);
            order.push(c);
        }
        Ok(())
    };
    while let Some(best) = best_class(tried) {
        for k in (0..EFFECTS.len()).filter(|k| !best.has(*k)) {
            attempt(best.with(k), tried)?;
        }
        let Some(after) = best_class(tried).filter(|c| *c != best) else { break };
        for k in after.indices() {
            attempt(after.without(k), tried)?;
        }
    }
    Ok(order)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Searches from the baseline and single-effect classes with the
    /// evidences `table` (by spelling; missing classes: −1e9).
    fn run(table: &[(&str, f64)]) -> (Option<Cause>, Vec<Cause>) {
        let z = |c: Cause| {
            table.iter().find(|(n, _)| Cause::parse(n) == Some(c)).map_or(-1e9, |(_, z)| *z)
        };
        let mut tried: Tried = Cause::ALL.iter().map(|c| (*c, Some(z(*c)))).collect();
        let order = search_classes::<()>(&mut tried, &|_| true, &mut |c| Ok(Some(z(c)))).unwrap();
        (best_class(&tried), order)
    }

    #[test]
    fn a_best_baseline_tries_nothing_more() {
        let (best, order) = run(&[("none", 0.0), ("perimeter-friction", -3.0)]);
        assert_eq!(best, Some(Cause::NONE));
        assert!(order.is_empty());
    }

    #[test]
    fn two_effects_acting_together_are_found_and_a_third_is_not_kept() {
        let table = [
            ("none", 0.0),
            ("perimeter-pounding", 40.0),
            ("perimeter-friction", 25.0),
            ("connection-hysteresis", -5.0),
            ("perimeter-pounding+perimeter-friction", 90.0),
            ("perimeter-pounding+connection-hysteresis", 35.0),
            ("perimeter-pounding+perimeter-friction+connection-hysteresis", 88.0),
        ];
        let (best, order) = run(&table);
        assert_eq!(best, Cause::parse("perimeter-pounding+perimeter-friction"));
        // Two pairs from pounding, then the triple from the best pair: the
        // other pairs are never needed.
        let names: Vec<&str> = order.iter().map(|c| c.as_str()).collect();
        assert_eq!(
            names,
            [
                "perimeter-pounding+perimeter-friction",
                "perimeter-pounding+connection-hysteresis",
                "perimeter-pounding+perimeter-friction+connection-hysteresis",
            ]
        );
    }

    #[test]
    fn a_class_whose_effect_costs_nothing_to_drop_is_left_backward() {
        // The triple beats the pair it came from, but one of its pairs
        // (without pounding) beats the triple: the search ends there.
        let table = [
            ("none", 0.0),
            ("perimeter-pounding", 10.0),
            ("perimeter-friction", 8.0),
            ("connection-hysteresis", 7.0),
            ("perimeter-pounding+perimeter-friction", 20.0),
            ("perimeter-pounding+perimeter-friction+connection-hysteresis", 30.0),
            ("perimeter-friction+connection-hysteresis", 31.0),
        ];
        let (best, order) = run(&table);
        assert_eq!(best, Cause::parse("perimeter-friction+connection-hysteresis"));
        assert!(order.len() <= 5, "{order:?}");
    }

    #[test]
    fn classes_out_of_place_or_without_evidence_are_never_the_best() {
        let mut tried: Tried =
            [(Cause::NONE, Some(0.0)), (Cause::PERIMETER_FRICTION, Some(5.0))].into();
        let fixed = |c: Cause| !c.has(0); // no sliding ends for pounding
        let order = search_classes::<()>(&mut tried, &fixed, &mut |_| Ok(None)).unwrap();
        assert_eq!(order, [Cause::PERIMETER_FRICTION.with(2)]);
        assert_eq!(best_class(&tried), Some(Cause::PERIMETER_FRICTION));
    }
}
