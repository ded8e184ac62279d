//! Which elements each node belongs to: the incidence the per-particle passes read.

/// The corners of `elements` (tetrahedra, triangles: `N` corners each) around each of `n`
/// nodes: `slots[offsets[i]..offsets[i + 1]]` are the slots `N e + c` with corner `c` of element
/// `e` equal to `i`, in increasing `e` (`offsets` has `n + 1` entries).
pub(crate) fn corners_around<const N: usize>(
    elements: &[[u32; N]],
    n: usize,
) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; n + 1];
    for element in elements {
        element.iter().for_each(|&k| offsets[k as usize + 1] += 1);
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut next = offsets.clone();
    let mut slots = vec![0u32; offsets[n] as usize];
    for (e, element) in elements.iter().enumerate() {
        for (c, &k) in element.iter().enumerate() {
            slots[next[k as usize] as usize] = (N * e + c) as u32;
            next[k as usize] += 1;
        }
    }
    (offsets, slots)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_corner_is_listed_once_under_its_node_in_tetrahedron_order() {
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4], [4, 0, 2, 5]];
        let (offsets, slots) = corners_around(&tets, 6);
        assert_eq!(offsets, vec![0, 2, 4, 7, 9, 11, 12]);
        for i in 0..6 {
            let mine = &slots[offsets[i] as usize..offsets[i + 1] as usize];
            assert!(mine.windows(2).all(|w| w[0] < w[1]));
            for &s in mine {
                assert_eq!(tets[s as usize / 4][s as usize % 4] as usize, i);
            }
        }
    }
}
