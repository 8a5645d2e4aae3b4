"""The PA9 plant with every state measured, its fault detector and both UIO banks, with thresholds
set from 30 healthy noisy runs: the setting of the bank-alarm figure's tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import uio_teach as ut


@dataclass
class BankSetting:
    plant: ut.Plant
    detector: object
    t: np.ndarray
    banks: list
    healthy: list
    thresholds: list


def bank_setting() -> BankSetting:
    pa9 = ut.examples.pa9()
    plant = ut.Plant(pa9.A, np.eye(3), B=pa9.B, E=pa9.E)
    detector = ut.design_uio(plant, poles=[-1, -2, -3])
    t = np.linspace(0, 6, 601)
    banks = [ut.design_uio_bank(plant, kind, poles=[-2, -3, -4]) for kind in ("actuator", "sensor")]
    healthy = [ut.simulate_fault(plant, detector, t, noise=0.01, seed=k) for k in range(30)]
    ths = [bank.thresholds(healthy, false_alarm_rate=0.05, window=0.5) for bank in banks]
    return BankSetting(plant, detector, t, banks, healthy, ths)
