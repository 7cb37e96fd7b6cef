"""Tables 3, 4 and 5 of Kovarik (2016), transcribed as printed.

Source: B. Kovarik, *Modeling of the Nonlinear Frequency Dependent Engine Mount Dynamic
Stiffness*, Master's thesis, University of Zagreb, 2016, sec. 3.2 "Triple mass oscillator
verification" (the reference text has no page numbers; the tables follow the paragraph on the
MSC Nastran SOL 108 deck of Appendix A):

* Table 3 -- calculated engine mass displacement x1 [mm],
* Table 4 -- calculated transmitted force F_T to the ground (chassis) node [N],
* Table 5 -- calculated cross-point dynamic stiffness K_CP [N/mm],

each at 5, 10, 12, 15, 17, 20, 25, 30 and 40 Hz, in four columns (Analytical, MSC Nastran,
AVL Excite, MSC Adams), real and imaginary part. Set-up: the Appendix A deck
(``mounts/thesis-appendix-a.toml``), a 100 kg engine mass under a 100 N harmonic force.

The values are kept as the printed text, so that the unit of the last printed digit is known
(e.g. the Analytical column prints ``-0.034`` where the Nastran column prints ``-0.0340``).
Nothing here is computed: this module only parses the transcription.
"""

from __future__ import annotations

import numpy as np

#: Column order of each row: real and imaginary part of each of the four sources.
SOURCES = ("analytical", "nastran", "excite", "adams")

#: Frequencies of Tables 3-5 [Hz].
FREQUENCIES_HZ = (5.0, 10.0, 12.0, 15.0, 17.0, 20.0, 25.0, 30.0, 40.0)

# f | Analytical re im | MSC Nastran re im | AVL Excite re im | MSC Adams re im
_TABLE3_X1_MM = """
5   -0.3644 -0.6746  -0.3653 -0.6750  -0.3644 -0.6746  -0.3656 -0.6753
10  -0.0787 -0.034   -0.0787 -0.0340  -0.0787 -0.0340  -0.0787 -0.0340
12  -0.0492 -0.0243  -0.0492 -0.0243  -0.0492 -0.0243  -0.0492 -0.0243
15  -0.0284 -0.019   -0.0285 -0.0190  -0.0284 -0.0190  -0.0285 -0.0190
17  -0.0215 -0.0173  -0.0216 -0.0173  -0.0215 -0.0173  -0.0215 -0.0173
20  -0.0158 -0.0155  -0.0158 -0.0155  -0.0158 -0.0155  -0.0158 -0.0155
25  -0.0114 -0.013   -0.0114 -0.0130  -0.0114 -0.0130  -0.0114 -0.0130
30  -0.0094 -0.0107  -0.0094 -0.0107  -0.0094 -0.0107  -0.0094 -0.0107
40  -0.0073 -0.0071  -0.0073 -0.0071  -0.0073 -0.0071  -0.0073 -0.0071
"""

_TABLE4_FT_N = """
5   -16.5 -210.1  -16.7 -210.3  -16.5 -210.1  -16.9 -210.3
10  -18.3  -34.1  -18.4  -34.1  -18.3  -34.1  -18.3  -34.1
12  -17.0  -26.2  -17.1  -26.2  -17.0  -26.2  -17.0  -26.1
15  -12.9  -15.2  -13.0  -15.1  -12.9  -15.2  -12.9  -15.1
17   -9.7  -12.1   -9.7  -12.0   -9.7  -12.1   -9.7  -12.1
20   -6.9   -9.9   -7.0   -9.8   -6.9   -9.9   -6.9   -9.9
25   -5.0   -7.7   -5.1   -7.7   -5.0   -7.7   -5.0   -7.7
30   -4.2   -6.2   -4.2   -6.2   -4.2   -6.2   -4.2   -6.2
40   -3.3   -4.0   -3.3   -4.0   -3.3   -4.0   -3.3   -4.0
"""

_TABLE5_KCP_N_PER_MM = """
5   251.3 111.4  251.4 111.1  251.3 111.4  251.3 111.1
10  354.4 280.7  354.6 280.2  354.4 280.6  354.1 279.8
12  490.0 290.7  490.1 289.8  489.5 290.3  488.8 289.7
15  560.8 158.4  560.1 157.5  561.3 157.9  559.0 158.5
17  546.3 121.4  545.3 120.7  547.2 121.1  546.4 121.3
20  536.8  98.1  535.5  97.5  535.8  98.4  534.8  98.7
25  528.3  74.9  527.3  73.2  527.8  74.4  527.4  74.8
30  518.5  63.7  520.0  62.4  520.0  63.4  520.0  63.4
40  503.2  61.6  503.4  58.4  504.7  59.8  504.0  59.1
"""


def _last_digit(text: str) -> float:
    """Unit of the last printed digit of a number written as ``-0.0340`` -> 1e-4."""
    if "." not in text:
        return 1.0
    return 10.0 ** -len(text.split(".")[1])


def _parse(block: str) -> dict:
    rows = [line.split() for line in block.strip().splitlines()]
    freq = np.array([float(r[0]) for r in rows])
    if tuple(freq) != FREQUENCIES_HZ:
        raise ValueError("transcription: unexpected frequencies")
    out = {"frequency_hz": freq}
    for j, src in enumerate(SOURCES):
        re_txt = [r[1 + 2 * j] for r in rows]
        im_txt = [r[2 + 2 * j] for r in rows]
        out[src] = np.array([complex(float(a), float(b)) for a, b in zip(re_txt, im_txt)])
        out[src + "_digit_real"] = np.array([_last_digit(t) for t in re_txt])
        out[src + "_digit_imag"] = np.array([_last_digit(t) for t in im_txt])
        out[src + "_text"] = list(zip(re_txt, im_txt))
    return out


def load() -> dict:
    """The three tables as printed.

    Returns
    -------
    dict
        ``{"table3": ..., "table4": ..., "table5": ...}``; each entry is a dict with
        ``frequency_hz`` [Hz] and, for each source in :data:`SOURCES`, the complex values
        (``x1`` [mm], ``F_T`` [N], ``K_CP`` [N/mm]), the unit of the last printed digit of
        the real and imaginary parts (``<source>_digit_real``, ``<source>_digit_imag``) and
        the printed text (``<source>_text``).
    """
    return {"table3": _parse(_TABLE3_X1_MM), "table4": _parse(_TABLE4_FT_N),
            "table5": _parse(_TABLE5_KCP_N_PER_MM)}
