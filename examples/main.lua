-- The default main job of `scripts/run`: for now, settle a 3D sample of
-- 2,000 spheres in a box (the lab-test issue replaces it with a
-- servo-controlled triaxial series).
arg = {"2000", "40000"}
dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "settle3d.lua")
