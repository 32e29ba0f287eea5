-- seixo.lab.material: the rock's bonded-particle micro-parameters
-- (lab.rock) and the stiffness of the walls that load its balls.
local check = require "seixo.check"
local tables = require "seixo.lab.tables"
local copy, merge = tables.copy, tables.merge
local material = {}

-- Potyondy & Cundall's (2004) PFC2D micro-parameters of Lac du Bonnet
-- granite (their Table 1): in 2D they give the granite's E and UCS
-- (docs/potyondy-cundall.md).
local granite2d = {
  density = 2630, modulus = 62e9, stiffness_ratio = 2.5, friction = 0.5, damping = 0.7,
  bond = {radius_multiplier = 1, modulus = 62e9, stiffness_ratio = 2.5,
          tensile_strength = 157e6, tensile_strength_sd = 36e6, cohesion = 157e6, cohesion_sd = 36e6},
}

-- The same granite calibrated in 3D: with the 2D moduli a sphere packing
-- is softer (E 50 instead of 69 GPa) and weaker (UCS 150 instead of 200
-- MPa), so the moduli and strengths are scaled by the BPM's scalings (E
-- with Ec = Ec-bar, the UCS with sigma-bar_c = tau-bar_c, the ratios and
-- the coefficient of variation kept): seixo's calibration, measured in
-- docs/potyondy-cundall.md, not P&C's PFC3D table.
local granite3d = merge(granite2d, {
  modulus = 87e9,
  bond = {modulus = 87e9, tensile_strength = 227e6, tensile_strength_sd = 52e6, cohesion = 227e6, cohesion_sd = 52e6},
})

--- Bonded-particle micro-parameters (4-49 ... 4-53) of a granite-like rock
--- after Potyondy & Cundall (2004, Lac du Bonnet granite), with overrides.
--- over.dim = 3 starts from the set calibrated in 3D, 2 (or none) from
--- P&C's PFC2D set.
function material.rock(over)
  if over ~= nil and type(over) ~= "table" then error("lab.rock: a table of overrides expected, got " .. type(over), 2) end
  local dim = over and over.dim
  if dim ~= nil and dim ~= 2 and dim ~= 3 then error("lab.rock: dim must be 2 or 3 (got " .. tostring(dim) .. ")", 2) end
  if dim then over = copy(over); over.dim = nil end
  local mat = merge(dim == 3 and granite3d or granite2d, over)
  -- stiffnesses given as kn or ks: the rock's modulus, which would take
  -- their place (a modulus > 0 sets kn and ks), is not taken with them (a
  -- sand's kn = 1e8 became 6.2e10 from the granite: a user's finding)
  if over and (over.kn ~= nil or over.ks ~= nil) and over.modulus == nil then
    -- the one not given follows from the other by the stiffness ratio (the
    -- override's, or the rock's 2.5), not from m:material's default 1e8
    local ratio = mat.stiffness_ratio
    if over.ks == nil and type(mat.kn) == "number" then mat.ks = mat.kn / ratio end
    if over.kn == nil and type(mat.ks) == "number" then mat.kn = mat.ks * ratio end
    mat.modulus, mat.stiffness_ratio = nil, nil
  end
  -- its keys and values checked now, as m:material checks them (a
  -- misspelt key was otherwise named only by the lab.specimen it reached)
  local why = check.material_error(mat)
  if why then error("lab.rock: " .. why, 2) end
  return mat
end

-- The normal stiffness of a ball of radius r of material mat (4-49), for walls.
function material.ball_kn(mat, r, dim)
  if mat.modulus and mat.modulus > 0 then return dim == 3 and 4 * r * mat.modulus or 2 * mat.modulus end
  return mat.kn
end

return material
