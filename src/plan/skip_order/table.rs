//! The exact block orders of [`super`] for blocks of [`TABLE_MIN_LINES`] to
//! [`super::EXACT_MAX_LINES`] lines, as its Held–Karp solver gives them: a pure
//! function of three small integers (lines, `min_gap`, a next block or not), looked up instead
//! of solved (a block of 20 lines took ~5 ms to solve). Written by the ignored test
//! `print_the_table_of_exact_orders` and checked entry by entry against the solver by
//! `the_table_of_exact_orders_is_the_solvers` (plan::skip_order::tests).

use super::EXACT_MAX_LINES;

/// Smallest block in the table, lines (smaller ones solve in well under a millisecond).
pub(crate) const TABLE_MIN_LINES: usize = 12;

/// The characters of line numbers 0–19 in [`ORDERS`].
pub(crate) const DIGITS: &[u8; 20] = b"0123456789abcdefghij";

/// The exact order of a block of `n` lines with `min_gap` and `next_block`, when the table
/// holds it. `min_gap` beyond `n` is looked up as `n`: every move of the block (and the move
/// on to the next block) is short for either, so the solver's costs, and its order, agree.
pub(crate) fn exact_order(n: usize, min_gap: usize, next_block: bool) -> Option<Vec<usize>> {
    if !(TABLE_MIN_LINES..=EXACT_MAX_LINES).contains(&n) {
        return None;
    }
    // Entries by n, then min_gap 0..=n, then next_block (false, true).
    let before: usize = (TABLE_MIN_LINES..n).map(|m| 2 * (m + 1)).sum();
    let k = before + 2 * min_gap.min(n) + usize::from(next_block);
    let entry = ORDERS.get(k)?.as_bytes();
    let lines: Option<Vec<usize>> = entry
        .iter()
        .map(|c| DIGITS.iter().position(|d| d == c))
        .collect();
    lines.filter(|l| l.len() == n)
}

/// Every entry: the line numbers in driving order, one [`DIGITS`] character each.
#[rustfmt::skip]
static ORDERS: [&str; 306] = [
    "0123456789ab", "0123456789ab", "0123456789ab", "0123456789ab",
    "0246a8b97531", "02413579b86a", "0396a7b84152", "036a7b841529",
    "0483a6b72951", "04b73a629518", "05a49382716b", "05a49382b617",
    "06718293a4b5", "06718293a4b5", "078192a3b456", "0768192a3b45",
    "0891a2b34567", "0876591a2b34", "09a1b2345678", "0987654a1b23",
    "0ab123456789", "0a9876543b12", "0ba987654321", "0ba987654321",
    "0123456789ab", "0123456789ab", "0123456789abc", "0123456789abc",
    "0123456789abc", "0123456789abc", "02468b9ca7531", "02413579ca86b",
    "036a7b8c94152", "03625149c8b7a", "04b7c83a62951", "04b7c83a51629",
    "05a49382b617c", "05a493c72b618", "06c5b4a392817", "06c5b4a392817",
    "078192a3b4c56", "078192a3b4c56", "0891a2b3c4567", "087691a2b3c45",
    "09a1b2c345678", "098765a1b2c34", "0ab1c23456789", "0a987654b1c23",
    "0bc123456789a", "0ba9876543c12", "0cba987654321", "0cba987654321",
    "0123456789abc", "0123456789abc", "0123456789abcd", "0123456789abcd",
    "0123456789abcd", "0123456789abcd", "02468cadb97531", "0241357968bdac",
    "03625147ad9c8b", "03625147ad9c8b", "04a3b7c8d95162", "04b73c8d95162a",
    "05a493c7d82b61", "05a4d83c72b619", "06c5b4a392817d", "06c5b4a392d718",
    "078192a3b4c5d6", "078192a3b4c5d6", "0891a2b3c4d567", "08791a2b3c4d56",
    "09a1b2c3d45678", "09876a1b2c3d45", "0ab1c2d3456789", "0a98765b1c2d34",
    "0bc1d23456789a", "0ba987654c1d23", "0cd123456789ab", "0cba9876543d12",
    "0dcba987654321", "0dcba987654321", "0123456789abcd", "0123456789abcd",
    "0123456789abcde", "0123456789abcde", "0123456789abcde", "0123456789abcde",
    "02468adbec97531", "0241357968acebd", "03625147ad9c8be", "03625147ad9eb8c",
    "04b73c8d9ea5162", "04c8d9ea516273b", "05a4d8e93c72b61", "05c4d8e93b6172a",
    "06c5b4a392d718e", "06c5b4a3e82d719", "07e6d5c4b3a2918", "07e6d5c4b3a2918",
    "0891a2b3c4d5e67", "0891a2b3c4d5e67", "09a1b2c3d4e5678", "0987a1b2c3d4e56",
    "0ab1c2d3e456789", "0a9876b1c2d3e45", "0bc1d2e3456789a", "0ba98765c1d2e34",
    "0cd1e23456789ab", "0cba987654d1e23", "0de123456789abc", "0dcba9876543e12",
    "0edcba987654321", "0edcba987654321", "0123456789abcde", "0123456789abcde",
    "0123456789abcdef", "0123456789abcdef", "0123456789abcdef", "0123456789abcdef",
    "02468aecfdb97531", "0241357968acfdbe", "0369daebfc852741", "0369cfbea741528d",
    "04c8d9eafb516273", "048d9eafb516273c", "05c4d8e9fa3b6172", "05e9fa4d83c6172b",
    "06c5b4a3e8f92d71", "06c5b4f93e82d71a", "07e6d5c4b3a2918f", "07e6d5c4b3a2f819",
    "0891a2b3c4d5e6f7", "0891a2b3c4d5e6f7", "09a1b2c3d4e5f678", "098a1b2c3d4e5f67",
    "0ab1c2d3e4f56789", "0a987b1c2d3e4f56", "0bc1d2e3f456789a", "0ba9876c1d2e3f45",
    "0cd1e2f3456789ab", "0cba98765d1e2f34", "0de1f23456789abc", "0dcba987654e1f23",
    "0ef123456789abcd", "0edcba9876543f12", "0fedcba987654321", "0fedcba987654321",
    "0123456789abcdef", "0123456789abcdef", "0123456789abcdefg", "0123456789abcdefg",
    "0123456789abcdefg", "0123456789abcdefg", "02468acfdgeb97531", "0241357968acegdbf",
    "0369fcgdaeb852741", "038bfcgda7415269e", "048d9eafbgc516273", "048372615cgbfae9d",
    "05c4d83e9fagb6172", "05d4e9fagb617283c", "06c5b4f9ga3e82d71", "06e5c4f9ga3d7182b",
    "07e6d5c4b3a2f819g", "07e6d5c4b3g92f81a", "08g7f6e5d4c3b2a19", "08g7f6e5d4c3b2a19",
    "09a1b2c3d4e5f6g78", "09a1b2c3d4e5f6g78", "0ab1c2d3e4f5g6789", "0a98b1c2d3e4f5g67",
    "0bc1d2e3f4g56789a", "0ba987c1d2e3f4g56", "0cd1e2f3g456789ab", "0cba9876d1e2f3g45",
    "0de1f2g3456789abc", "0dcba98765e1f2g34", "0ef1g23456789abcd", "0edcba987654f1g23",
    "0fg123456789abcde", "0fedcba9876543g12", "0gfedcba987654321", "0gfedcba987654321",
    "0123456789abcdefg", "0123456789abcdefg", "0123456789abcdefgh", "0123456789abcdefgh",
    "0123456789abcdefgh", "0123456789abcdefgh", "02468acgehfdb97531", "0241357968acehfdbg",
    "0369cfb841527aehdg", "0369cgdheb841527af", "0483726159dhcgbfae", "0483726159dhcgbfae",
    "05d4e9fagbhc617283", "05e94fagbhc617283d", "06e5c4f9gahb3d7182", "06e5gahb4f93d7182c",
    "07e6d5c4b3g9ha2f81", "07e6d5c4ha3g92f81b", "08g7f6e5d4c3b2a19h", "08g7f6e5d4c3b2h91a",
    "09a1b2c3d4e5f6g7h8", "09a1b2c3d4e5f6g7h8", "0ab1c2d3e4f5g6h789", "0a9b1c2d3e4f5g6h78",
    "0bc1d2e3f4g5h6789a", "0ba98c1d2e3f4g5h67", "0cd1e2f3g4h56789ab", "0cba987d1e2f3g4h56",
    "0de1f2g3h456789abc", "0dcba9876e1f2g3h45", "0ef1g2h3456789abcd", "0edcba98765f1g2h34",
    "0fg1h23456789abcde", "0fedcba987654g1h23", "0gh123456789abcdef", "0gfedcba9876543h12",
    "0hgfedcba987654321", "0hgfedcba987654321", "0123456789abcdefgh", "0123456789abcdefgh",
    "0123456789abcdefghi", "0123456789abcdefghi", "0123456789abcdefghi", "0123456789abcdefghi",
    "02468acehfigdb97531", "0241357968acebdgifh", "0369cgda741528bfieh", "0369cfiehda741528bg",
    "0483726159dhcgbfaei", "0483726159dhcgbieaf", "05e94fagbhcid617283", "05fagbhcid61728394e",
    "06e5gahbic4f93d7182", "06f5gahbic4e718293d", "07e6d5c4haib3g92f81", "07g6e5d4haib3f8192c",
    "08g7f6e5d4c3b2h91ai", "08g7f6e5d4c3ia2h91b", "09i8h7g6f5e4d3c2b1a", "09i8h7g6f5e4d3c2b1a",
    "0ab1c2d3e4f5g6h7i89", "0ab1c2d3e4f5g6h7i89", "0bc1d2e3f4g5h6i789a", "0ba9c1d2e3f4g5h6i78",
    "0cd1e2f3g4h5i6789ab", "0cba98d1e2f3g4h5i67", "0de1f2g3h4i56789abc", "0dcba987e1f2g3h4i56",
    "0ef1g2h3i456789abcd", "0edcba9876f1g2h3i45", "0fg1h2i3456789abcde", "0fedcba98765g1h2i34",
    "0gh1i23456789abcdef", "0gfedcba987654h1i23", "0hi123456789abcdefg", "0hgfedcba9876543i12",
    "0ihgfedcba987654321", "0ihgfedcba987654321", "0123456789abcdefghi", "0123456789abcdefghi",
    "0123456789abcdefghij", "0123456789abcdefghij", "0123456789abcdefghij", "0123456789abcdefghij",
    "02468aceigjhfdb97531", "0241357968acebdfhjgi", "0369c8bheifjgda74152", "038beifjgda7415269ch",
    "04837bgchdiejfa62951", "048chdiejfb7395162ag", "05fagbhcidje61728394", "05agbhcidje61728394f",
    "06f5e4gahbicjd718293", "06f5ga4hbicjd718293e", "07g6e5d4haibjc3f8192", "07g6e5ibjc4ha3f8192d",
    "08g7f6e5d4c3iajb2h91", "08g7f6e5d4jb3ia2h91c", "09i8h7g6f5e4d3c2b1aj", "09i8h7g6f5e4d3c2ja1b",
    "0ab1c2d3e4f5g6h7i8j9", "0ab1c2d3e4f5g6h7i8j9", "0bc1d2e3f4g5h6i7j89a", "0bac1d2e3f4g5h6i7j89",
    "0cd1e2f3g4h5i6j789ab", "0cba9d1e2f3g4h5i6j78", "0de1f2g3h4i5j6789abc", "0dcba98e1f2g3h4i5j67",
    "0ef1g2h3i4j56789abcd", "0edcba987f1g2h3i4j56", "0fg1h2i3j456789abcde", "0fedcba9876g1h2i3j45",
    "0gh1i2j3456789abcdef", "0gfedcba98765h1i2j34", "0hi1j23456789abcdefg", "0hgfedcba987654i1j23",
    "0ij123456789abcdefgh", "0ihgfedcba9876543j12", "0jihgfedcba987654321", "0jihgfedcba987654321",
    "0123456789abcdefghij", "0123456789abcdefghij",
];
