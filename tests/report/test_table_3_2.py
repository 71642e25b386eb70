"""Table 3.2 in HTML (jointcal.report.table_3_2): no value the posterior does not
support, the GA's points as members of the posterior's set, bounds touched; the landing page's flags."""
from __future__ import annotations

import pandas as pd

from jointcal.calibrate import PARAMS, CalibrateSettings
from jointcal.report.summary import bound_hits, ga_best_point, landing_html
from jointcal.report.table_3_2 import table_3_2_html

BOUNDS = CalibrateSettings().full_bounds  # the Ministack kind's defaults


def _table(zeta_v=1e-4):
    rows = []
    for p in PARAMS:
        v = {"Fs": 36.6, "KT": 5.1e5, "chi": -0.65, "beta": 0.135, "k": 1e6, "zeta_v": zeta_v}[p]
        rows.append(dict(assembly="first", param=p, unit="-", ga_optimum=v, posterior_median=v,
                         posterior_q05=v / 2 if p != "chi" else v - 0.01, posterior_q95=v * 2 if p != "chi" else v + 0.01,
                         width_ratio=0.8 if p == "beta" else 0.1, constrained=p != "beta"))
    return pd.DataFrame(rows)


def test_table_3_2_html_gives_no_value_the_posterior_does_not_support():
    history = pd.DataFrame({"generation": [0, 1], "objective": [3.0, 2.0], "Fs": [10.0, 42.1], "KT": [1e5, 4.6e5],
                            "chi": [-0.5, -0.59], "beta": [0.1, 0.0013], "k": [1e5, 9.97e5], "zeta_v": [0.01, 0.0019]})
    ga = ga_best_point(history)
    assert ga["Fs"] == 42.1 and ga["objective"] == 2.0
    modes = pd.DataFrame([dict(mode=k, weight=w, param=p, median=m, q05=m, q95=m) for k, (w, m) in
                          enumerate([(0.87, 1561.0), (0.13, 37.3)]) for p in PARAMS])
    identified = pd.DataFrame({"quantity": PARAMS, "identified": [False, True, True, False, False, True]})
    html = table_3_2_html(_table(), {"first": ga}, {"first": modes}, BOUNDS, identified={"first": identified})
    assert html.count("<tr>") == 1 + 5  # header, posterior, two modes, polished optimum, GA best
    assert html.count("not identified") == 3  # Fs, beta, k: in the posterior row, and no value in any other
    for value in ("36.6", "42.1", "0.135", "0.0013", "9.97e5", "1e6"):  # Fs, beta, k values, in no row
        assert f">{value}<" not in html and f">{value} " not in html, value
    assert "5.1e5<br><small>[2.55e5, 1.02e6]</small>" in html  # KT identified: median and 90% interval
    assert "spans 18.3 to 73.2 (bounds)" in html  # the range the bounds leave Fs, not a value
    # the GA's points as members: the GA best's chi -0.59 and zeta_v 0.0019 lie outside their intervals, its KT
    # 4.6e5 inside; the polished optimum sits at the medians here
    assert html.count("outside the 90% interval") == 2 and ">4.6e5<" in html
    assert "touches lower bound" in html and "class=\"bound\"" in html  # zeta_v's interval reaches 1e-4
    assert "(between modes)" in html and "mode 2 (13% of the draws)" in html
    assert bound_hits({p: v for p, v in zip(PARAMS, [36.6, 5.1e5, -0.65, 0.135, 1e6, 1e-4])}, BOUNDS) == {
        "zeta_v": "lower"}
    page = landing_html(runs=pd.DataFrame({"run_id": ["a", "b"], "flags": ["", "clipped; snr"]}),
                        modal=pd.DataFrame({"run_id": ["a", "b"], "flags": ["", "unusable"]}),
                        status={"first": (False, "NOT converged: 10.2 tau")}, notes={"first": ["MULTIMODAL (2 modes)"]},
                        verdict="<ol><li>the verdict</li></ol>")
    assert page.index("the verdict") < page.index("Run flags")
    assert "<b>1</b> of 2 runs (clipped: 1; snr: 1)" in page and "NOT converged: 10.2 tau" in page
