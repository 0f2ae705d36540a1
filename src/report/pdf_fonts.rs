//! The two standard PDF fonts the figures use, without embedding: Helvetica in
//! WinAnsiEncoding and Symbol in its built-in encoding. [`encode`] splits a text into runs of
//! one font each; [`text_width`] measures it from the fonts' AFM advance widths.
//!
//! Characters outside both fonts have a documented fallback (see [`encode`]): the minus sign
//! U+2212 becomes an en dash, superscripts `^` and the plain character, subscripts the plain
//! character, `‖` two bars, letters with a dot or tilde above not in WinAnsi their base letter,
//! combining marks are dropped, and anything else is `?`.

/// The font of a run of text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PdfFont {
    /// Helvetica, WinAnsiEncoding (resource `/F1`).
    Helvetica,
    /// Symbol, its built-in encoding (resource `/F2`): Greek letters and mathematical signs.
    Symbol,
}

/// A run of text in one font: the font and its one-byte character codes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Run {
    /// The font of the run.
    pub font: PdfFont,
    /// Character codes in the font's encoding.
    pub codes: Vec<u8>,
}

/// The WinAnsiEncoding code of `c`, if Helvetica has it there.
fn win_ansi(c: char) -> Option<u8> {
    let u = c as u32;
    if (32..=126).contains(&u) || (160..=255).contains(&u) {
        return Some(u as u8);
    }
    Some(match c {
        '\u{20AC}' => 128,
        '\u{201A}' => 130,
        '\u{0192}' => 131,
        '\u{201E}' => 132,
        '\u{2026}' => 133,
        '\u{2020}' => 134,
        '\u{2021}' => 135,
        '\u{02C6}' => 136,
        '\u{2030}' => 137,
        '\u{0160}' => 138,
        '\u{2039}' => 139,
        '\u{0152}' => 140,
        '\u{017D}' => 142,
        '\u{2018}' => 145,
        '\u{2019}' => 146,
        '\u{201C}' => 147,
        '\u{201D}' => 148,
        '\u{2022}' => 149,
        '\u{2013}' => 150,
        '\u{2014}' => 151,
        '\u{02DC}' => 152,
        '\u{2122}' => 153,
        '\u{0161}' => 154,
        '\u{203A}' => 155,
        '\u{0153}' => 156,
        '\u{017E}' => 158,
        '\u{0178}' => 159,
        // The minus sign: an en dash has the digits' width in Helvetica.
        '\u{2212}' => 150,
        _ => return None,
    })
}

/// The Symbol code of `c`, if the Symbol font has it.
fn symbol(c: char) -> Option<u8> {
    SYMBOL
        .binary_search_by_key(&c, |e| e.0)
        .ok()
        .map(|k| SYMBOL[k].1)
}

/// The plain character of a superscript (`⁻` → `-`, `ᵀ` → `T`).
fn superscript(c: char) -> Option<char> {
    Some(match c {
        '\u{2070}' => '0',
        '\u{00B9}' => '1',
        '\u{00B2}' => '2',
        '\u{00B3}' => '3',
        '\u{2074}'..='\u{2079}' => char::from(b'4' + (c as u32 - 0x2074) as u8),
        '\u{207A}' => '+',
        '\u{207B}' => '-',
        '\u{207C}' => '=',
        '\u{207D}' => '(',
        '\u{207E}' => ')',
        '\u{207F}' => 'n',
        '\u{2071}' => 'i',
        '\u{1D40}' => 'T',
        '\u{1D4F}' => 'k',
        _ => return None,
    })
}

/// The plain character of a subscript (`₂` → `2`, `ᵢ` → `i`).
fn subscript(c: char) -> Option<char> {
    Some(match c {
        '\u{2080}'..='\u{2089}' => char::from(b'0' + (c as u32 - 0x2080) as u8),
        '\u{208A}' => '+',
        '\u{208B}' => '-',
        '\u{208C}' => '=',
        '\u{208D}' => '(',
        '\u{208E}' => ')',
        '\u{1D62}' => 'i',
        '\u{2C7C}' => 'j',
        '\u{2090}' => 'a',
        '\u{2091}' => 'e',
        '\u{2092}' => 'o',
        '\u{2093}' => 'x',
        '\u{2096}' => 'k',
        '\u{2099}' => 'n',
        '\u{209A}' => 'p',
        '\u{209B}' => 's',
        '\u{209C}' => 't',
        _ => return None,
    })
}

/// The fallback text of a character neither font has (`None`: dropped).
fn fallback(c: char) -> Option<&'static str> {
    Some(match c {
        '\u{2016}' => "||",
        '\u{2223}' => "|",
        '\u{2225}' => "||",
        '\u{2308}' | '\u{230A}' => "[",
        '\u{2309}' | '\u{230B}' => "]",
        '\u{2713}' | '\u{2714}' => "yes",
        '\u{2717}' | '\u{2718}' => "no",
        '\u{1E57}' => "p",
        '\u{1E8B}' => "x",
        '\u{1E8F}' => "y",
        '\u{1E61}' => "s",
        '\u{1EF9}' => "y",
        '\u{011D}' => "g",
        '\u{0307}' | '\u{0302}' | '\u{0303}' | '\u{0304}' | '\u{0308}' => return None,
        c if ('\u{0300}'..='\u{036F}').contains(&c) => return None,
        c if c.is_whitespace() || c.is_control() => " ",
        _ => "?",
    })
}

/// Splits `text` into runs of one font each, with the fallbacks of the module documentation:
/// Helvetica (WinAnsiEncoding) where it has the character, Symbol where it has it, otherwise
/// the fallback in Helvetica. A run of superscripts all in WinAnsi (`¹ ² ³`) is kept;
/// any other run of superscripts is written `^` and its plain characters (`10⁻⁵` → `10^-5`).
pub fn encode(text: &str) -> Vec<Run> {
    let chars: Vec<char> = text.chars().collect();
    let mut runs: Vec<Run> = Vec::new();
    let mut push = |font: PdfFont, code: u8| match runs.last_mut() {
        Some(r) if r.font == font => r.codes.push(code),
        _ => runs.push(Run {
            font,
            codes: vec![code],
        }),
    };
    let mut k = 0;
    while k < chars.len() {
        let c = chars[k];
        if superscript(c).is_some() {
            let end = (k..chars.len())
                .find(|&j| superscript(chars[j]).is_none())
                .unwrap_or(chars.len());
            let run = &chars[k..end];
            if run.iter().all(|&s| win_ansi(s).is_some()) {
                run.iter()
                    .filter_map(|&s| win_ansi(s))
                    .for_each(|b| push(PdfFont::Helvetica, b));
            } else {
                push(PdfFont::Helvetica, b'^');
                run.iter()
                    .filter_map(|&s| superscript(s))
                    .for_each(|s| push(PdfFont::Helvetica, s as u8));
            }
            k = end;
            continue;
        }
        if let Some(b) = win_ansi(c) {
            push(PdfFont::Helvetica, b);
        } else if let Some(b) = symbol(c) {
            push(PdfFont::Symbol, b);
        } else if let Some(s) = subscript(c) {
            push(PdfFont::Helvetica, s as u8);
        } else if let Some(f) = fallback(c) {
            f.bytes().for_each(|b| push(PdfFont::Helvetica, b));
        }
        k += 1;
    }
    runs
}

/// The advance width of character `code` of `font` [1/1000 em].
pub fn code_width(font: PdfFont, code: u8) -> u16 {
    match font {
        PdfFont::Helvetica => code
            .checked_sub(32)
            .map_or(0, |k| HELVETICA[usize::from(k)]),
        PdfFont::Symbol => SYMBOL.iter().find(|e| e.1 == code).map_or(0, |e| e.2),
    }
}

/// The advance width of `runs` [em]: multiply by the font size for points.
pub fn runs_width(runs: &[Run]) -> f64 {
    runs.iter()
        .flat_map(|r| r.codes.iter().map(|&c| f64::from(code_width(r.font, c))))
        .sum::<f64>()
        / 1000.0
}

/// The advance width of `text` as [`encode`] writes it [em].
pub fn text_width(text: &str) -> f64 {
    runs_width(&encode(text))
}

/// Advance widths of Helvetica [1/1000 em] by WinAnsiEncoding code, codes 32..=255
/// (0: no glyph at that code). From Adobe's Helvetica AFM (as shipped with groff).
pub(super) const HELVETICA: [u16; 224] = [
    278, 278, 355, 556, 556, 889, 667, 191, 333, 333, 389, 584, 278, 333, 278, 278, 556, 556, 556,
    556, 556, 556, 556, 556, 556, 556, 278, 278, 584, 584, 584, 556, 1015, 667, 667, 722, 722, 667,
    611, 778, 722, 278, 500, 667, 556, 833, 722, 778, 667, 778, 722, 667, 611, 722, 667, 944, 667,
    667, 611, 278, 278, 278, 469, 556, 333, 556, 556, 500, 556, 556, 278, 556, 556, 222, 222, 500,
    222, 833, 556, 556, 556, 556, 333, 500, 278, 556, 500, 722, 500, 500, 500, 334, 260, 334, 584,
    0, 556, 0, 222, 556, 333, 1000, 556, 556, 333, 1000, 667, 333, 1000, 0, 611, 0, 0, 222, 222,
    333, 333, 350, 556, 1000, 333, 1000, 500, 333, 944, 0, 500, 667, 278, 333, 556, 556, 556, 556,
    260, 556, 333, 737, 370, 556, 584, 333, 737, 333, 400, 584, 333, 333, 333, 578, 537, 278, 333,
    333, 365, 556, 834, 834, 834, 611, 667, 667, 667, 667, 667, 667, 1000, 722, 667, 667, 667, 667,
    278, 278, 278, 278, 722, 722, 778, 778, 778, 778, 778, 584, 778, 722, 722, 722, 722, 667, 667,
    611, 556, 556, 556, 556, 556, 556, 889, 500, 556, 556, 556, 556, 278, 278, 278, 278, 556, 556,
    556, 556, 556, 556, 556, 584, 611, 556, 556, 556, 556, 500, 556, 500,
];

/// Characters drawn with the Symbol font: (Unicode, Symbol code, width [1/1000 em]),
/// sorted by Unicode. Widths from Adobe's Symbol AFM (as shipped with groff).
pub(super) const SYMBOL: [(char, u8, u16); 115] = [
    ('\u{0391}', 65, 722),   // Α Alpha
    ('\u{0392}', 66, 667),   // Β Beta
    ('\u{0393}', 71, 603),   // Γ Gamma
    ('\u{0394}', 68, 612),   // Δ Delta
    ('\u{0395}', 69, 611),   // Ε Epsilon
    ('\u{0396}', 90, 611),   // Ζ Zeta
    ('\u{0397}', 72, 722),   // Η Eta
    ('\u{0398}', 81, 741),   // Θ Theta
    ('\u{0399}', 73, 333),   // Ι Iota
    ('\u{039A}', 75, 722),   // Κ Kappa
    ('\u{039B}', 76, 686),   // Λ Lambda
    ('\u{039C}', 77, 889),   // Μ Mu
    ('\u{039D}', 78, 722),   // Ν Nu
    ('\u{039E}', 88, 645),   // Ξ Xi
    ('\u{039F}', 79, 722),   // Ο Omicron
    ('\u{03A0}', 80, 768),   // Π Pi
    ('\u{03A1}', 82, 556),   // Ρ Rho
    ('\u{03A3}', 83, 592),   // Σ Sigma
    ('\u{03A4}', 84, 611),   // Τ Tau
    ('\u{03A5}', 85, 690),   // Υ Upsilon
    ('\u{03A6}', 70, 763),   // Φ Phi
    ('\u{03A7}', 67, 722),   // Χ Chi
    ('\u{03A8}', 89, 795),   // Ψ Psi
    ('\u{03A9}', 87, 768),   // Ω Omega
    ('\u{03B1}', 97, 631),   // α alpha
    ('\u{03B2}', 98, 549),   // β beta
    ('\u{03B3}', 103, 411),  // γ gamma
    ('\u{03B4}', 100, 494),  // δ delta
    ('\u{03B5}', 101, 439),  // ε epsilon
    ('\u{03B6}', 122, 494),  // ζ zeta
    ('\u{03B7}', 104, 603),  // η eta
    ('\u{03B8}', 113, 521),  // θ theta
    ('\u{03B9}', 105, 329),  // ι iota
    ('\u{03BA}', 107, 549),  // κ kappa
    ('\u{03BB}', 108, 549),  // λ lambda
    ('\u{03BC}', 109, 576),  // μ mu
    ('\u{03BD}', 110, 521),  // ν nu
    ('\u{03BE}', 120, 493),  // ξ xi
    ('\u{03BF}', 111, 549),  // ο omicron
    ('\u{03C0}', 112, 549),  // π pi
    ('\u{03C1}', 114, 549),  // ρ rho
    ('\u{03C2}', 86, 439),   // ς sigma1
    ('\u{03C3}', 115, 603),  // σ sigma
    ('\u{03C4}', 116, 439),  // τ tau
    ('\u{03C5}', 117, 576),  // υ upsilon
    ('\u{03C6}', 102, 521),  // φ phi
    ('\u{03C7}', 99, 549),   // χ chi
    ('\u{03C8}', 121, 686),  // ψ psi
    ('\u{03C9}', 119, 686),  // ω omega
    ('\u{03D1}', 74, 631),   // ϑ theta1
    ('\u{03D2}', 161, 620),  // ϒ Upsilon1
    ('\u{03D5}', 106, 603),  // ϕ phi1
    ('\u{03D6}', 118, 713),  // ϖ omega1
    ('\u{2032}', 162, 247),  // ′ minute
    ('\u{2033}', 178, 411),  // ″ second
    ('\u{2044}', 164, 167),  // ⁄ fraction
    ('\u{2111}', 193, 686),  // ℑ Ifraktur
    ('\u{2118}', 195, 987),  // ℘ weierstrass
    ('\u{211C}', 194, 795),  // ℜ Rfraktur
    ('\u{2135}', 192, 823),  // ℵ aleph
    ('\u{2190}', 172, 987),  // ← arrowleft
    ('\u{2191}', 173, 603),  // ↑ arrowup
    ('\u{2192}', 174, 987),  // → arrowright
    ('\u{2193}', 175, 603),  // ↓ arrowdown
    ('\u{2194}', 171, 1042), // ↔ arrowboth
    ('\u{21D0}', 220, 987),  // ⇐ arrowdblleft
    ('\u{21D1}', 221, 603),  // ⇑ arrowdblup
    ('\u{21D2}', 222, 987),  // ⇒ arrowdblright
    ('\u{21D3}', 223, 603),  // ⇓ arrowdbldown
    ('\u{21D4}', 219, 1042), // ⇔ arrowdblboth
    ('\u{2200}', 34, 713),   // ∀ universal
    ('\u{2202}', 182, 494),  // ∂ partialdiff
    ('\u{2203}', 36, 549),   // ∃ existential
    ('\u{2205}', 198, 823),  // ∅ emptyset
    ('\u{2206}', 68, 612),   // ∆ Delta
    ('\u{2207}', 209, 713),  // ∇ gradient
    ('\u{2208}', 206, 713),  // ∈ element
    ('\u{2209}', 207, 713),  // ∉ notelement
    ('\u{220B}', 39, 439),   // ∋ suchthat
    ('\u{220F}', 213, 823),  // ∏ product
    ('\u{2211}', 229, 713),  // ∑ summation
    ('\u{2217}', 42, 500),   // ∗ asteriskmath
    ('\u{221A}', 214, 549),  // √ radical
    ('\u{221D}', 181, 713),  // ∝ proportional
    ('\u{221E}', 165, 713),  // ∞ infinity
    ('\u{2220}', 208, 768),  // ∠ angle
    ('\u{2227}', 217, 603),  // ∧ logicaland
    ('\u{2228}', 218, 603),  // ∨ logicalor
    ('\u{2229}', 199, 768),  // ∩ intersection
    ('\u{222A}', 200, 768),  // ∪ union
    ('\u{222B}', 242, 274),  // ∫ integral
    ('\u{2234}', 92, 863),   // ∴ therefore
    ('\u{223C}', 126, 549),  // ∼ similar
    ('\u{2245}', 64, 549),   // ≅ congruent
    ('\u{2248}', 187, 549),  // ≈ approxequal
    ('\u{2260}', 185, 549),  // ≠ notequal
    ('\u{2261}', 186, 549),  // ≡ equivalence
    ('\u{2264}', 163, 549),  // ≤ lessequal
    ('\u{2265}', 179, 549),  // ≥ greaterequal
    ('\u{2282}', 204, 713),  // ⊂ propersubset
    ('\u{2283}', 201, 713),  // ⊃ propersuperset
    ('\u{2284}', 203, 713),  // ⊄ notsubset
    ('\u{2286}', 205, 713),  // ⊆ reflexsubset
    ('\u{2287}', 202, 713),  // ⊇ reflexsuperset
    ('\u{2295}', 197, 768),  // ⊕ circleplus
    ('\u{2297}', 196, 768),  // ⊗ circlemultiply
    ('\u{22A5}', 94, 658),   // ⊥ perpendicular
    ('\u{22C5}', 215, 250),  // ⋅ dotmath
    ('\u{25CA}', 224, 494),  // ◊ lozenge
    ('\u{2660}', 170, 753),  // ♠ spade
    ('\u{2663}', 167, 753),  // ♣ club
    ('\u{2665}', 169, 753),  // ♥ heart
    ('\u{2666}', 168, 753),  // ♦ diamond
    ('\u{3008}', 225, 329),  // 〈 angleleft
    ('\u{3009}', 241, 329),  // 〉 angleright
];
