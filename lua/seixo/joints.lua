-- seixo.joints: flat-jointed rock for seixo.lab (Potyondy 2012), beside the
-- parallel-bonded rock of lab.rock, and the comparison of the two on the
-- same specimens (UCS, Brazilian tensile strength, friction angle).
--
--   local joints = require("seixo.joints")
--   local spec = lab.specimen{..., model = "flatjoint", material = joints.rock()}
--   local t = joints.compare{dim = 2, out = "cmp"}   -- UCS/BTS and phi of both
local lab = require("seixo.lab")

local joints = {}

local function merge(base, over)
  local t = {}
  for k, v in pairs(base) do t[k] = type(v) == "table" and merge(v, {}) or v end
  for k, v in pairs(over or {}) do t[k] = type(v) == "table" and type(t[k]) == "table" and merge(t[k], v) or v end
  return t
end

--- Flat-joint micro-parameters of a granite-like rock, with overrides: the
--- grains' stiffness of lab.rock, faces of radius min(RA, RB) cut into 4
--- segments (2D) or 2 rings x 4 sectors (3D), elements much stronger in
--- shear than in tension (so the faces fail in tension and then resist by
--- friction and interlock, the flat joint's point), a few slits.
function joints.rock(over)
  return lab.rock(merge({
    bond = {radius_multiplier = 1, modulus = 62e9, stiffness_ratio = 2.5, tensile_strength = 35e6,
            tensile_strength_sd = 7e6, cohesion = 350e6, cohesion_sd = 70e6, friction_angle = 0, friction = 0.6,
            elements = 4, sectors = 4, unbonded_fraction = 0.1},
  }, over))
end

--- UCS, biaxial (or triaxial) and Brazilian tests of a parallel-bonded and a
--- flat-jointed rock on the same specimens (genesis seed, size). opts: dim,
--- width, height, diameter, radius, seed, confining (for phi; default
--- {0, 5e6, 10e6}), parallel and flatjoint (material overrides), out (CSV
--- and figure prefix), log. Returns {parallel = row, flatjoint = row} with
--- rows {ucs, bts, ratio, phi, c}.
function joints.compare(opts)
  opts = opts or {}
  local dim = opts.dim or 2
  local out = opts.out or "joints_compare"
  local radius = opts.radius or {0.4e-3, 0.66e-3}
  local confining = opts.confining or {0, 5e6, 10e6}
  local res = {}
  for _, model in ipairs{"parallel", "flatjoint"} do
    local mat = model == "flatjoint" and joints.rock(opts.flatjoint) or lab.rock(opts.parallel)
    local common = {dim = dim, radius = radius, seed = opts.seed or 3, model = model, material = mat,
                    log = opts.log}
    local spec = lab.specimen(merge(common, {shape = dim == 3 and "cylinder" or "rect", width = opts.width or 0.01,
                                             diameter = opts.width or 0.01, height = opts.height or 0.02,
                                             path = out .. "_" .. model .. "_ucs.h5"}))
    local disk = lab.specimen(merge(common, {shape = dim == 3 and "disc" or "disk", diameter = opts.diameter or 0.012,
                                             thickness = opts.thickness, path = out .. "_" .. model .. "_bts.h5"}))
    local s = lab.series(spec, {confining = confining, out = out .. "_" .. model, log = opts.log})
    local b = lab.brazilian(disk, {log = opts.log})
    local ucs = s.tests[1].peak
    res[model] = {ucs = ucs, bts = b.tensile_strength, ratio = ucs / b.tensile_strength, phi = s.fit.phi, c = s.fit.c}
  end
  local rows = {}
  for i, model in ipairs{"parallel", "flatjoint"} do
    local r = res[model]
    rows[i] = {i, r.ucs / 1e6, r.bts / 1e6, r.ratio, r.phi, r.c / 1e6}
  end
  lab.write_csv(out .. ".csv", {"model", "ucs_MPa", "bts_MPa", "ucs_over_bts", "phi_deg", "c_MPa"}, rows)
  return res
end

return joints
