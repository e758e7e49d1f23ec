/*
 * element.h — element physics shared by the structure kinds (not installed; issue 24).
 *
 * The home of what a beam element contributes, independent of the kind that assembles it:
 * today the strain energy of a Hermite bending element and of an axial/torsion bar (used by
 * the mode labels of both kinds).  The kinds' element matrices (fe.c planar, fe3.c spatial)
 * are the other half of it; a new element (Timoshenko, a 6x6 cross-section) adds its
 * stiffness, mass, geometric and energy parts here and in those files.
 */
#ifndef SM_ELEMENT_H
#define SM_ELEMENT_H

/** a . b for 3-vectors. */
double smi_dot3(const double *a, const double *b);
/** x' K x of the Hermite bending stiffness EI/l^3 [12 6l -12 6l; . 4l^2 -6l 2l^2; ...] on
 *  (v1, v1', v2, v2'): twice the bending strain energy. */
double smi_elem_bending_energy(double EI, double l, double v1, double s1, double v2, double s2);
/** k/l (a2 - a1)^2: twice the strain energy of a bar of stiffness k (EA or GJ) and length l. */
double smi_elem_bar_energy(double k, double l, double a1, double a2);

#endif
