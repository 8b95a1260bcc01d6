// The fracture and laser settings of a separating-tissue scene, with the defaults we
// chose and where they come from (the separation-forces paper gives no values).
//
// Fracture (paper Sec. V.F). J_c [J/m^2], the toughness of the connection between the
// layers: 75 J/m^2, the dissection energy of soft-tissue layers torn apart by peeling —
// Sommer, Gasser, Regitnig, Auer & Holzapfel, "Dissection properties of the human aortic
// media: an experimental study", J. Biomech. Eng. 130(2):021007 (2008), report about
// 5 mJ/cm^2 circumferentially and 7.6 mJ/cm^2 axially (50 and 76 J/m^2). l_n and l_t [m],
// the crack front a blunt tool opens per unit travel normal to and along the interface.
// l_t = 6 mm, our choice: the tip of a 5 mm laparoscopic dissector and the flap it lifts on
// either side. l_n = 12 mm: fracture holds a pull at F_n only where l_n is at least the
// length the fields need at the crack front (holding_normal_length in fracture_step.h),
// which is shortest at the free rim and longest inside the interface; 12 mm is the round
// length that clears every node of the default two-layer scene, so a pull beside a groove
// holds as one at the rim does. So F_n = J_c l_n = 0.9 N and F_t = J_c l_t = 0.45 N by
// default (Eqs. 11, 14).
// Friction between the tool and an exposed layer, mu = 0.2: our choice for wet tissue on
// steel (a setting; the paper's sliding follows Hayward & Armstrong's model [28]).
//
// Laser (paper Sec. V.G), the procedure of the paper's prostate simulator: holmium:YAG
// laser enucleation of the prostate (HoLEP, its ref. [32]), typically 80–100 W through a
// 550 um end-firing fibre (e.g. Gilling et al., J. Endourol. 12(5):457–459, 1998):
// P = 80 W, l_f = 0.55 mm. alpha = 0.5, the share of the delivered power that vaporises
// tissue: the 2.1 um light is absorbed within about 0.4 mm of water (absorption
// coefficient near 26/cm: Hale & Querry, "Optical constants of water in the 200-nm to
// 200-um wavelength region", Appl. Opt. 12(3):555–563, 1973) and water reflects only ~2 %
// at normal incidence, but the heated rim (the coagulation zone) takes part of it: our
// choice, a setting. Tissue as water (the paper's footnote 1, after Jacques [6]):
// rho = 1000 kg/m^3, c_p = 4180 J/(kg K), dT = 63 K (37 -> 100 degC), H = 2.26 MJ/kg
// (latent heat of vaporisation at 100 degC). Then q = rho (c_p dT + H) = 2.52 GJ/m^3 and
// v_s = alpha P / (q l_f^2) = 52 mm/s (Eqs. 18–20).
#pragma once

namespace cohaptic {

struct FractureSettings {
  double toughness = 75;             ///< J_c [J/m^2]
  double normal_length = 0.012;      ///< l_n [m]
  double tangential_length = 0.006;  ///< l_t [m]
  double friction = 0.2;             ///< mu, tool on an exposed layer
};

struct TissueThermal {
  double density = 1000;         ///< rho [kg/m^3]
  double specific_heat = 4180;   ///< c_p [J/(kg K)]
  double temperature_rise = 63;  ///< dT, body temperature to boiling [K]
  double latent_heat = 2.26e6;   ///< H [J/kg]
};

struct LaserSettings {
  double power = 80;               ///< P [W]
  double absorbed_fraction = 0.5;  ///< alpha
  double spot_diameter = 0.55e-3;  ///< l_f [m]
  /// The fibre vaporises the interface only when its tip is this close to it [m]
  /// (about the depth the beam stays focused at the spot size).
  double reach = 1e-3;
};

struct SeparationSettings {
  FractureSettings fracture;
  LaserSettings laser;
  TissueThermal tissue;
  double force_limit = 4;  ///< [N] the haptic output is scaled down to this
};

/// Throws Error naming the setting that is not a positive finite number (friction >= 0,
/// absorbed fraction in (0, 1]).
void validate(const SeparationSettings& settings);

/// q = rho (c_p dT + H) [J/m^3] (Eq. 19).
double vaporisation_energy_density(const TissueThermal& tissue);

/// v_s = alpha P / (q l_f^2) [m/s] (Eq. 20).
double vaporisation_speed(const LaserSettings& laser, const TissueThermal& tissue);

}  // namespace cohaptic
