"""The report "Kinematics and Dynamics of Phantom Model 1.5 Haptic Interface": its
parameters and their adapter to links in full (``parameters``), its corrected equations
(``closed_form``), the independent SymPy derivation (``derivation``) and the appendix's
printed torques (``appendix``)."""
