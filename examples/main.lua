-- The default main job of `scripts/run`: a servo-controlled triaxial series
-- (UCS and three confining stresses) on a bonded granite-like specimen,
-- with the Mohr-Coulomb fit, a quasi-static check and the figures, written
-- to lab-results/ (see examples/triaxial.lua).
arg = {"lab-results"}
dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "triaxial.lua")
