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

/// Most names a message lists: a message stays a line or two however many
/// names a scene defines.
pub const MAX_LISTED: usize = 8;

/// `candidates`, each written by `show`, for a message such as "defined
/// materials: …": all of them, in their order, when there are at most
/// [`MAX_LISTED`]; otherwise the [`MAX_LISTED`] closest to `name` by edit
/// distance (the closest first, ties in their order) and how many more
/// there are. Every message that lists names goes through here.
pub fn listing<'a, I>(name: &str, candidates: I, show: impl Fn(&str) -> String) -> String
where
    I: IntoIterator<Item = &'a str>,
{
    let mut names: Vec<&str> = candidates.into_iter().collect();
    let more = names.len().saturating_sub(MAX_LISTED);
    if more > 0 {
        let lower = name.to_lowercase();
        // Edit distance costs the product of the lengths: a name far longer
        // than the one asked for is cut first (it cannot be close anyway).
        let limit = lower.chars().count() * 2 + 8;
        let mut scored: Vec<(usize, usize, &str)> = names
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let short: String = c.to_lowercase().chars().take(limit).collect();
                (edit_distance(&lower, &short), i, *c)
            })
            .collect();
        scored.select_nth_unstable(MAX_LISTED - 1);
        scored.truncate(MAX_LISTED);
        scored.sort_unstable();
        names = scored.into_iter().map(|(_, _, c)| c).collect();
    }
    let mut text = names.iter().map(|n| show(n)).collect::<Vec<_>>().join(", ");
    if more > 0 {
        text.push_str(&format!(" and {more} more"));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn listings_are_short_and_start_with_the_closest_names() {
        let few = ["b", "a", "c"];
        assert_eq!(listing("x", few, |n| format!("`{n}`")), "`b`, `a`, `c`");
        assert_eq!(listing("x", Vec::<&str>::new(), str::to_string), "");
        let many: Vec<String> = (0..200_000).map(|i| format!("material{i}")).collect();
        let text = listing("material7", many.iter().map(String::as_str), str::to_string);
        assert!(text.starts_with("material7, "), "{text}");
        assert!(text.ends_with(" and 199992 more"), "{text}");
        assert_eq!(text.matches(", ").count(), MAX_LISTED - 1, "{text}");
        assert!(text.len() < 200, "{text}");
    }

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
