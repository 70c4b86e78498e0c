"""Two antennas beside the RT-70: a 12-m class Cassegrain and a 34-m class beam waveguide.

One job: hold the :class:`~rt70.scenes.antenna.AntennaSpec` of each, every number with
its source — stated in a cited public text, derived from such numbers by a stated rule,
or assumed where no source was reached (docs/antennas.md has the table and the
references). The bandwidths are the ones :mod:`rt70.telescope.servo_design` tunes on
each model (``rt70 servo``; rounded down to three digits), written in so that a run
need not tune again.
"""

from __future__ import annotations

from rt70.scenes.antenna import AntennaSpec

#: A 12-m class az–el Cassegrain antenna (ALMA class).
ANTENNA_12M = AntennaSpec(
    name="antenna_12m",
    diameter=12.0,
    focal_ratio=0.4,
    optics="cassegrain",
    elevation_mass=54e3,
    azimuth_mass=54e3,
    locked_rotor_hz=(6.0, 6.0),
    rate_limit_deg_s=(6.0, 3.0),
    acceleration_deg_s2=(10.7, 10.7),
    elevation_range_deg=(2.0, 88.0),
    azimuth_range_deg=(-270.0, 270.0),
    design_wind=15.0,
    position_bandwidth_hz=(1.51, 1.63),
    sources={
        "diameter, optics": "ALMA Project Book ch. 4, Table 4.1 (stated)",
        "focal_ratio": "f = 4.8 m, ALMA Memo 339 via astrohack alma_dv (secondary)",
        "masses": "108 t total, El/Az 50/50 (VertexRSI prototype, Mangum 2006 slide 5): "
        "54 t each (derived)",
        "locked_rotor_hz": "'lowest resonant frequency of approx 6 Hz' (MMA antenna WG "
        "minutes, 6 Jan 1998; a design target, preliminary)",
        "rate_limit_deg_s": "6 / 3 deg/s (ACA antennas, arXiv:1106.3472)",
        "acceleration_deg_s2": "fast switching 1.5 deg in 1.5 s (Table 4.1), the move in "
        "half the time: 4 x 1.5 / 0.75^2 = 10.7 deg/s^2 (derived)",
        "ranges, design_wind, secondary": "not found: assumed",
        "position_bandwidth_hz": "tuned on this model by rt70.telescope.servo_design",
    },
)

#: A 34-m class az–el beam-waveguide antenna (NASA DSN class).
ANTENNA_34M = AntennaSpec(
    name="antenna_34m",
    diameter=34.0,
    focal_ratio=0.4,
    optics="beam_waveguide",
    elevation_mass=250e3,
    azimuth_mass=250e3,
    locked_rotor_hz=(1.89, 5.70),
    rate_limit_deg_s=(0.8, 0.8),
    acceleration_deg_s2=(0.4, 0.4),
    elevation_range_deg=(6.0, 89.5),
    azimuth_range_deg=(-225.0, 225.0),
    design_wind=20.0,
    position_bandwidth_hz=(0.485, 1.51),
    sources={
        "diameter, optics": "JPL DSN 34-m antennas page; CDSCC DSS-34 (stated)",
        "elevation_mass": "dish 125 t lifted as one piece (ATNF, 22 Aug 2015), doubled "
        "for its counterweight and backup structure (assumed)",
        "azimuth_mass": "not found: assumed equal to the elevation structure's",
        "locked_rotor_hz": "not found: the RT-70's 0.92 / 2.77 Hz scaled by 70/34 "
        "(fundamental frequency inversely proportional to the diameter, Gawronski 2008 "
        "sec. 3.2.5) (derived)",
        "rate_limit_deg_s": "0.8 deg/s (CDSCC DSS-34; DSN 810-005 module 302)",
        "acceleration_deg_s2": "0.4 deg/s^2 (DSN 810-005 module 302 Table 1, as transcribed "
        "by SDRAST/MonitorControl) (secondary)",
        "ranges": "elevation 6 ... 89.5 deg, azimuth +-225 deg (810-005 302, secondary)",
        "design_wind": "20 m/s: the stow wind, 72 km/h (CDSCC DSS-34)",
        "focal_ratio, secondary": "not found: assumed",
        "position_bandwidth_hz": "tuned on this model by rt70.telescope.servo_design",
    },
)

#: The presets by scene name.
PRESETS = {spec.name: spec for spec in (ANTENNA_12M, ANTENNA_34M)}
