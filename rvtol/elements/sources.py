"""How each element of the reducer chain (:mod:`.reducer_chain`) was modelled from the design: the source line
recorded beside its stiffness (``ReducerChain.sources``), as templates the chain fills with the design's numbers
(``str.format`` fields named after them).

A leaf module (no imports): the chain formats these when it is built from a design.
"""

CRANK = "stepped Timoshenko shaft ⌀{journal:g}/⌀{eccentric:g} mm, supports {span:g} mm apart"
CRANK_SUPPORT = ("tapered roller pair ({arrangement}), {rollers} rollers × {length:g} mm, α = {alpha_deg:.2f}°, "
                 "preload {preload:g} N (Δ = {interference_um:.2f} µm)")
PIN_GROOVE = "conforming pin-in-hole contact, pin r {rp:g} in groove r {rg:g} mm (radial clearance {clearance_um:.3g} µm)"
INPUT_SHAFT = "⌀{d:g} × {length:g} mm solid shaft, K = G J / L"
CARRIER_JOINTS = ("{bolts} × M{d:g} 10.9 per pillar, VDI 2230 preload {preload:.4g} N (opening margin {open:.3g} MPa, "
                  "slip margin {slip:.4g} N at rated), interface Ra {ra_um:g} µm: tilt {tilt:.3g} rad/N·mm, shear "
                  "{shear:.3g} µm/kN")
CARRIER = ("{pillars} pillars {w:g} × {t:g} × {h:g} mm at R {R:g} (fixed–guided, Cowper κ, twist), end plate {te:g} / "
           "flange {tf:g} mm as Kirchhoff plates clamped at {a:g} mm around a pillar root")
DISC_WEB = "annulus r {ri:.2f} … {ro:.2f} mm (crank-hole edge to tooth root), t = disc width"
NEEDLE = ("needle row {rollers} × {length:g} mm, Palmgren line contact with its roller load distribution (20-DOF: "
          "replaces doc 000's k0·P^0.1)")
DISC_SEATS = ("plane-stress FE disc (scikit-fem P2), mean work {work:.4g} N·mm at rated less the web's {web:.4g}: "
              "{compliance:.3g} µm/kN per crank hole")
CARRIER_SEATS = ("plane-stress FE end plate {te:g} mm / flange {tf:g} mm, cups ⌀{D:g} on r {a:.3f}, clamped at the "
                 "pillar roots: {end_plate:.3g} / {flange:.3g} µm/kN per cup")
CONTACT_ROUGHNESS = ("Greenwood–Williamson layer, σ = {sigma_um:.3g} µm, β = {beta_um:g} µm, at the rated pin loads on "
                     "the conforming contact arcs: {compliance:.3g} µm/kN per pin (energy-weighted)")
HOUSING_RING = ("plane-stress FE ring r {ri:.2f} … {ro:g} mm (clamped), t = pin length: {compliance:.3g} µm/kN per "
                "pin")
