"""The nonlinear sheet: model (element loop and material state), Newton driver, loads, problems."""
