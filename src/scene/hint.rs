//! "Did you mean …?" hints: the closest known name to a misspelt one.

/// Levenshtein edit distance between `a` and `b`, counted in characters.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = Vec::with_capacity(b.len() + 1);
        cur.push(i + 1);
        for (j, cb) in b.iter().enumerate() {
            let substitute = prev[j] + usize::from(ca != *cb);
            cur.push(substitute.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The candidate closest to `name`, if it is close enough to be a plausible
/// misspelling: at most a third of the longer name's length away (and at
/// least 2 edits are always allowed), so that `radus` suggests `radius` but
/// `colour` does not suggest `ior`. A name that is the first words of a
/// candidate (`samples` for `samples_per_pixel`) suggests it before any
/// other (`sampler` is a single edit away, but less likely meant); a shorter
/// start of a name counts when no candidate is close by edits.
pub fn closest<'a, I>(name: &str, candidates: I) -> Option<&'a str>
where
    I: IntoIterator<Item = &'a str>,
{
    let lower = name.to_lowercase();
    let candidates: Vec<&str> = candidates.into_iter().collect();
    let first_words = format!("{lower}_");
    if let Some(c) = candidates
        .iter()
        .find(|c| c.to_lowercase().starts_with(&first_words))
    {
        return Some(c);
    }
    let by_edits = candidates
        .iter()
        .map(|&c| (edit_distance(&lower, &c.to_lowercase()), c))
        .filter(|&(d, c)| d <= (name.chars().count().max(c.chars().count()) / 3).max(2))
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c);
    by_edits.or_else(|| {
        (lower.chars().count() >= 3)
            .then(|| {
                candidates
                    .iter()
                    .copied()
                    .find(|c| c.to_lowercase().starts_with(&lower))
            })
            .flatten()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_counts_edits() {
        assert_eq!(edit_distance("", ""), 0);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("radius", "radus"), 1);
        assert_eq!(edit_distance("abc", ""), 3);
        assert_eq!(edit_distance("é", "e"), 1);
    }

    #[test]
    fn closest_suggests_only_plausible_names() {
        let fields = ["center", "radius", "material"];
        assert_eq!(closest("radus", fields), Some("radius"));
        assert_eq!(closest("centre", fields), Some("center"));
        assert_eq!(closest("Material", fields), Some("material"));
        assert_eq!(closest("colour", fields), None);
        assert_eq!(closest("mat", fields), Some("material"));
        assert_eq!(closest("ma", fields), None);
        assert_eq!(closest("x", Vec::<&str>::new()), None);
    }
}
