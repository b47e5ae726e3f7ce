//! Triangle lists from the strips and fans of mesh formats (glTF's modes 5 and 6), for the
//! model loader and for the exports that read a model again (both mesh its faces).

/// The triangles of a strip: each index after the first two closes one with the two before
/// it, every other one wound back so that all face the same way (glTF 2.0, §3.7.2.1).
pub fn strip_triangles(indices: &[u32]) -> Vec<[u32; 3]> {
    (2..indices.len())
        .map(|k| {
            if k % 2 == 0 {
                [indices[k - 2], indices[k - 1], indices[k]]
            } else {
                [indices[k - 1], indices[k - 2], indices[k]]
            }
        })
        .collect()
}

/// The triangles of a fan around its first index.
pub fn fan_triangles(indices: &[u32]) -> Vec<[u32; 3]> {
    (2..indices.len()).map(|k| [indices[0], indices[k - 1], indices[k]]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of four indices is two triangles wound alike; a fan of five, three around 0.
    #[test]
    fn strips_and_fans_unroll() {
        assert_eq!(strip_triangles(&[0, 1, 2, 3]), vec![[0, 1, 2], [2, 1, 3]]);
        assert_eq!(fan_triangles(&[0, 1, 2, 3, 4]), vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
        assert!(strip_triangles(&[0, 1]).is_empty() && fan_triangles(&[]).is_empty());
    }
}
