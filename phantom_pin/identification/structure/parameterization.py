"""The report's parameters, as the YAML holds them, and their affine map to the regressor's pi.

A vector ``x`` of the 20 *report parameters* (``NAMES``): the masses (kg) and diagonal
inertias (kg m^2, the report's segment axes) of segments A, C, BE and DF; the first moments
m l5 and m l6 (kg m) of BE and DF; I_baseyy (kg m^2, axis 1); the rotor inertia J (kg m^2, at
the motor shaft). As in the report, I_bexx, I_dfxx and I_baseyy include the reflected rotor
inertia J r^2; A and C are about their COM, BE and DF about the shoulder. Without public motor
data (the Touch) J is 0 and has no effect: the links carry the rotors (Actuation.rotor), and
no rotor inertia is written. The lengths l1..l3,
the hinge pins, the base's mass and x/z inertias and the transmission ratios are known
(taken from the configuration).

The report's adapter (phantom_pin.report.parameters.links) turns these numbers into the
URDF's links in full, and each link's standard parameters follow from its Inertial; all of
that is affine in ``x``, so pi(x) = A x + b (inertial and rotor columns of ``Regressor``) is
measured once per Description by finite differences, exactly (checked in tests), without
reading a file or running xacro.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin.config import Config
from phantom_pin.description.build import Description
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.identification.structure.cache import cached
from phantom_pin.report.parameters import ReportParameters, links

#: The report parameters, named by their --params key (first moments: mass * com).
NAMES = ("segment_a.mass", "segment_a.inertia.xx", "segment_a.inertia.yy", "segment_a.inertia.zz",
         "segment_c.mass", "segment_c.inertia.xx", "segment_c.inertia.yy", "segment_c.inertia.zz",
         "segment_be.mass", "segment_be.first_moment", "segment_be.inertia.xx",
         "segment_be.inertia.yy", "segment_be.inertia.zz",
         "segment_df.mass", "segment_df.first_moment", "segment_df.inertia.xx",
         "segment_df.inertia.yy", "segment_df.inertia.zz",
         "segment_g.inertia_yy", "actuation.motor.rotor_inertia")
#: The report's symbol of each (appendix names; m*l for the first moments).
SYMBOLS = ("ma", "Iaxx", "Iayy", "Iazz", "mc", "Icxx", "Icyy", "Iczz", "mbe", "mbe*l5", "Ibexx",
           "Ibeyy", "Ibezz", "mdf", "mdf*l6", "Idfxx", "Idfyy", "Idfzz", "Ibaseyy", "J")
MASSES = (0, 4, 8, 13)
ROTOR = 19


def report_of(config: Config) -> ReportParameters:
    """The report's numbers of ``config``; InvalidInputError unless it is written in the
    report's terms (the identification of the report's structure needs them)."""
    if config.report is None:
        raise InvalidInputError(f"{config.name} is not written in the report's terms (its links are "
                                "given in full); the report's structure cannot be identified on it", argument="model")
    return config.report


def report_vector(config: Config) -> np.ndarray:
    """``x`` of a configuration (its report numbers and rotor inertia)."""
    p = report_of(config)
    return np.array([p.ma, p.Iaxx, p.Iayy, p.Iazz, p.mc, p.Icxx, p.Icyy, p.Iczz, p.mbe,
                     p.mbe * p.l5, p.Ibexx, p.Ibeyy, p.Ibezz, p.mdf, p.mdf * p.l6, p.Idfxx,
                     p.Idfyy, p.Idfzz, p.Ibaseyy, config.actuation.rotor[0]])


def report_parameters(x: np.ndarray, config: Config) -> ReportParameters:
    """The ReportParameters of ``x``, lengths and g from ``config``."""
    v = dict(zip(SYMBOLS, np.asarray(x, float).tolist()))
    return dataclasses.replace(
        report_of(config), ma=v["ma"], Iaxx=v["Iaxx"], Iayy=v["Iayy"], Iazz=v["Iazz"], mc=v["mc"],
        Icxx=v["Icxx"], Icyy=v["Icyy"], Iczz=v["Iczz"], mbe=v["mbe"], l5=v["mbe*l5"] / v["mbe"],
        Ibexx=v["Ibexx"], Ibeyy=v["Ibeyy"], Ibezz=v["Ibezz"], mdf=v["mdf"], l6=v["mdf*l6"] / v["mdf"],
        Idfxx=v["Idfxx"], Idfyy=v["Idfyy"], Idfzz=v["Idfzz"], Ibaseyy=v["Ibaseyy"])


def overrides(x: np.ndarray, config: Config) -> dict[str, float]:
    """The --params keys of ``x``: first moments become segment_be.com = l5 and segment_df.com = l6
    (m); no rotor inertia for a configuration without public motor data."""
    out = {}
    for name, value in zip(NAMES, np.asarray(x, float)):
        out[name] = float(value)
    if config.actuation.motor is None:
        del out[NAMES[ROTOR]]
    out["segment_be.com"] = out.pop("segment_be.first_moment") / out["segment_be.mass"]
    out["segment_df.com"] = out.pop("segment_df.first_moment") / out["segment_df.mass"]
    return out


def tree_parameters(x: np.ndarray, description: Description, bodies: list[str]) -> np.ndarray:
    """pi without friction of the report parameters ``x``: the standard parameters of each
    tree body (``bodies``, link names with the description's prefix), then J r_i^2 (kg m^2)."""
    config = description.config
    ratios = np.array(config.actuation.rotor[1])
    if config.unprinted is None:
        raise InvalidInputError("the report's parameters need a model in the report's form", argument="description")
    linked = links(report_parameters(x, config), config.unprinted, float(x[ROTOR]), config.actuation.rotor[1])
    prefix = description.prefix
    inertial = [linked[name[len(prefix):]].dynamic_parameters() for name in bodies]
    return np.concatenate(inertial + [float(x[ROTOR]) * ratios**2])


def affine_map(description: Description, bodies: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """(A, b) with pi_without_friction = A x + b; A is (73, 20), for the tree bodies
    ``bodies`` (link names in Pinocchio's order: Regressor.bodies). Built once per
    Description (identification.cache), from the Config alone."""
    def compute() -> tuple[np.ndarray, np.ndarray]:
        x0 = report_vector(description.config)
        base = tree_parameters(x0, description, bodies)
        columns = []
        for k in range(len(NAMES)):
            # the map is affine; a small step keeps every link physical (1e-9 kg m^2 for J = 0
            # without public motor data, where J r^2 = 0 anyway)
            step = 1e-3 * abs(x0[k]) if x0[k] else 1e-9
            x = x0.copy()
            x[k] += step
            columns.append((tree_parameters(x, description, bodies) - base) / step)
        a = np.stack(columns, axis=1)
        return a, base - a @ x0

    a, b = cached(description, ("affine", tuple(bodies)), compute)
    return a.copy(), b.copy()
