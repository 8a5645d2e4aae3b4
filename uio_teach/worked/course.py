"""The registry entries of the course's three source documents (PA9, case study, missile)."""

from __future__ import annotations

from . import FigureEntry, WorkedExample

_FIGURES = "uio_teach.instructor.figures"

EXAMPLES = (
    WorkedExample(
        name="pa9",
        title="Practical Assignment 9",
        plant="uio_teach.examples:pa9",
        experiment="uio_teach.experiments:PA9",
        family="uio",
        scenario="uio_teach.explorers.scenarios:pa9_scenario",
        lab="lab_pa9.md",
        order=10,
        figures=(
            FigureEntry(
                "pa9_sine",
                "PA9 lab: sinusoidal disturbance d(t), error e and residual r of the UIO",
                f"{_FIGURES}:_pa9_sine",
            ),
            FigureEntry(
                "pa9_piecewise",
                "PA9 lab: piecewise-constant disturbance d(t), error e and residual r of the UIO",
                f"{_FIGURES}:_pa9_piecewise",
            ),
            FigureEntry(
                "pa9_states",
                "PA9: each state with its UIO estimate, error and residual (sinusoidal d)",
                f"{_FIGURES}:_pa9_states",
            ),
            FigureEntry(
                "pa9_luenberger",
                "PA9: UIO vs Luenberger observer, same poles, errors and residuals for both d",
                f"{_FIGURES}:_pa9_luenberger",
            ),
        ),
    ),
    WorkedExample(
        name="case_study",
        title="The discrete-time case study",
        plant="uio_teach.examples:dt_case_study",
        experiment="uio_teach.experiments:CASE_STUDY",
        family="pmo",
        scenario="uio_teach.explorers.scenarios:case_study_scenario",
        lab="lab_case_study.md",
        order=20,
        figures=(
            FigureEntry(
                "case_response",
                "Case study: states, estimates, error and residual with u2 and v both active",
                f"{_FIGURES}:_case_response",
            ),
            FigureEntry(
                "case_error",
                "Case study: error norm on a log scale, with and without the unknown signals",
                f"{_FIGURES}:_case_error",
            ),
        ),
    ),
    WorkedExample(
        name="missile",
        title="The missile autopilot",
        plant="uio_teach.examples:missile_autopilot",
        experiment="uio_teach.experiments:MISSILE",
        family="pmo",
        scenario="uio_teach.explorers.scenarios:missile_scenario",
        lab="lab_missile.md",
        order=30,
        figures=(
            FigureEntry(
                "missile_pmo",
                "Missile: x1..x4 with/without v and the PMO estimates (paper Fig. 4.1-4.4)",
                f"{_FIGURES}:_missile_pmo",
            ),
            FigureEntry(
                "missile_ginverse",
                "Missile: x1..x4 with/without v and the g-inverse estimates (Fig. 4.7-4.10)",
                f"{_FIGURES}:_missile_ginverse",
            ),
            FigureEntry(
                "missile_error",
                "Missile: estimation error of the PMO and the g-inverse observer, per state",
                f"{_FIGURES}:_missile_error",
            ),
            FigureEntry(
                "missile_inputs",
                "Missile: v1, v2 and their reconstructions by both observers (Fig. 4.5-4.6, "
                "4.11-4.12)",
                f"{_FIGURES}:_missile_inputs",
            ),
            FigureEntry(
                "missile_table2",
                "Missile: Table II, catch times (tol 2 %) next to the paper's, as .csv and .md",
                f"{_FIGURES}:_table2",
                table=True,
            ),
        ),
    ),
)
