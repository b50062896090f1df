# Blocked force and eccentricity (paper Figs. 7A/7B) and grasp logs (Fig. 8B).
# Filled in by the force work; without force datasets nothing here runs.
