"""clearance.builders: the mechanism catalogue. Builders return pure-data `Mechanism`s.

`CATALOGUE` maps each mechanism name to its builder and its `LinkageInfo` (topology,
clearable joints, joints of a criticality ranking, transmission angles, provenance);
`load_scenario` / `dump_scenario` read and write TOML scenario files. Every builder ends
with the same keywords (`ContactKeywords`: where the clearances are, their contact
properties, gravity, name), spelled out in its signature. This package never imports
MuJoCo.
"""

from clearance.builders._contact import ContactKeywords
from clearance.builders.catalogue import (
    CATALOGUE,
    CatalogueEntry,
    build,
    check_linkage,
    names,
)
from clearance.builders.four_bar import four_bar
from clearance.builders.multiloop import eight_bar, ten_bar
from clearance.builders.press import seven_bar_press
from clearance.builders.scenario import ScenarioError, dump_scenario, load_scenario
from clearance.builders.slider_crank import SLIDER_CRANK_JOINTS, rpm, slider_crank
from clearance.builders.stephenson import (
    stephenson_i,
    stephenson_i_slider,
    stephenson_ii_1,
    stephenson_ii_2,
)
from clearance.builders.watt import (
    watt_six_bar,
    watt_six_bar_slider_1,
    watt_six_bar_slider_2,
)

__all__ = [
    "slider_crank",
    "SLIDER_CRANK_JOINTS",
    "rpm",
    "four_bar",
    "watt_six_bar",
    "watt_six_bar_slider_1",
    "watt_six_bar_slider_2",
    "stephenson_i",
    "stephenson_i_slider",
    "stephenson_ii_1",
    "stephenson_ii_2",
    "eight_bar",
    "ten_bar",
    "seven_bar_press",
    "CATALOGUE",
    "CatalogueEntry",
    "build",
    "names",
    "check_linkage",
    "load_scenario",
    "dump_scenario",
    "ScenarioError",
    "ContactKeywords",
]
