-- seixo.joints: flat-jointed rock for seixo.lab (Potyondy 2012), beside the
-- parallel-bonded rock of lab.rock, and the comparison of the two on the
-- same specimens (UCS, Brazilian tensile strength, friction angle).
--
--   local joints = require("seixo.joints")
--   local spec = lab.specimen{..., model = "flatjoint", material = joints.rock()}
--   local t = joints.compare{dim = 2, out = "cmp"}   -- UCS/BTS and phi of both
--   local js = joints.jointed(spec, {angle = 60, cohesion = 20e6, friction_angle = 30, path = "j60.h5"})
--   local d = joints.direct_shear(spec, {normal_stress = 10e6, cohesion = 20e6, ...})
--   local c = joints.angle_series(spec, {angles = {0, 15, ..., 90}, cohesion = 20e6, ...})
local lab = require("seixo.lab")

local joints = {}

local c = require("seixo.check").module("joints", "lab.specimen, joints.jointed or lab.open")

local function merge(base, over)
  local t = {}
  for k, v in pairs(base) do t[k] = type(v) == "table" and merge(v, {}) or v end
  for k, v in pairs(over or {}) do t[k] = type(v) == "table" and type(t[k]) == "table" and merge(t[k], v) or v end
  return t
end

local function check_keys(fn, opts, keys)
  for k in pairs(opts) do
    if not keys[k] then error(string.format("joints.%s: unknown option '%s'", fn, tostring(k)), 3) end
  end
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
--- {0, 5e6, 10e6}), parallel and flatjoint (material overrides), gap and
--- gapped (the flat-jointed specimens' installation: lab.specimen's), out
--- (CSV and figure prefix), log. Returns {parallel = row, flatjoint = row} with
--- rows {ucs, bts, ratio, phi, c}.
function joints.compare(opts)
  opts = opts or {}
  c.log(opts.log, "compare") -- (up front: a number was called at the first line said)
  local dim = opts.dim or 2
  if opts.out ~= nil then c.prefix(opts.out, "compare") end
  local out = opts.out or "joints_compare"
  local radius = opts.radius or {0.4e-3, 0.66e-3}
  local confining = opts.confining or {0, 5e6, 10e6}
  local res = {}
  for _, model in ipairs{"parallel", "flatjoint"} do
    local mat = model == "flatjoint" and joints.rock(opts.flatjoint) or lab.rock(opts.parallel)
    local common = {dim = dim, radius = radius, seed = opts.seed or 3, model = model, material = mat,
                    log = opts.log}
    if model == "flatjoint" then common.gap, common.gapped = opts.gap, opts.gapped end
    local spec = lab.specimen(merge(common, {shape = dim == 3 and "cylinder" or "rect", width = opts.width or 0.01,
                                             diameter = opts.width or 0.01, height = opts.height or 0.02,
                                             path = out .. "_" .. model .. "_specimen.h5"}))
    local disk = lab.specimen(merge(common, {shape = dim == 3 and "disc" or "disk", diameter = opts.diameter or 0.012,
                                             thickness = opts.thickness, path = out .. "_" .. model .. "_disk.h5"}))
    -- (the series writes out_model_ucs.h5, the end of its UCS test: the specimen has a name of its own)
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

-- ------------------------------------------------------ tensile strength

--- The direct tension test of a bonded specimen (a 2D rect, a 3D cylinder
--- or prism, loading axis y in 2D and z in 3D): the balls within an eighth
--- of the height of either end are grips, fixed and pulled apart at
--- `strain_rate` (default lab's, 7e-8 of strain a step); the stress is the
--- pull of the specimen on the top grip over its section (2D: width x 1).
--- Stops when the stress falls below `post_peak` (default 0.5) times its
--- peak after a bond broke, or at max_steps (default 400,000). opts:
--- strain_rate, post_peak, every (steps a record, default 50), max_steps,
--- log. Returns {peak (Pa), strain_at_peak, cracks = {tension, shear} at
--- the peak, rows = {{strain, stress, pull of the bottom grip over the
--- section}, ...}, stopped}.
function joints.direct_tension(spec, opts)
  opts = opts or {}
  check_keys("direct_tension", opts, {strain_rate = true, post_peak = true, every = true, max_steps = true, log = true})
  c.log(opts.log, "direct_tension")
  local every = c.steps(opts.every or 50, "every", "direct_tension")
  local max_steps = c.steps(opts.max_steps or 400000, "max_steps", "direct_tension")
  c.specimen(spec, "direct_tension", {"path", "dim", "shape", "lo", "hi"})
  local dim = spec.dim
  if not (dim == 2 and spec.shape == "rect" or dim == 3 and (spec.shape == "cylinder" or spec.shape == "prism")) then
    error("joints.direct_tension: a 2D rect or a 3D cylinder or prism specimen", 2)
  end
  local m = c.load(spec, "direct_tension")
  local ax = dim
  local lo, hi = spec.lo[ax], spec.hi[ax]
  local h = hi - lo
  local area = spec.hi[1] - spec.lo[1]
  if dim == 3 then
    area = spec.shape == "cylinder" and math.pi / 4 * area ^ 2 or area * (spec.hi[2] - spec.lo[2])
  end
  local rate = opts.strain_rate or 7e-8 / m:timestep()
  local top, bottom = {}, {}
  for b in m:balls() do
    local y = b.pos[ax]
    if y > hi - h / 8 then top[#top + 1] = b elseif y < lo + h / 8 then bottom[#bottom + 1] = b end
  end
  local function pull(grip, v)
    for _, b in ipairs(grip) do
      b.fix = "all"
      local vel = dim == 3 and {0, 0, 0} or {0, 0}
      vel[ax] = v
      b.vel = vel
    end
  end
  pull(top, 0.5 * rate * h)
  pull(bottom, -0.5 * rate * h)
  local post_peak = opts.post_peak or 0.5
  local y0 = top[1].pos[ax] - bottom[1].pos[ax]
  local t0, s0 = m:crack_count("tension"), m:crack_count("shear")
  local rows, peak, at, stopped = {}, 0, nil, "max_steps"
  local steps = 0
  while steps < max_steps do
    local n = math.min(every, max_steps - steps) -- (max_steps exact, whatever every is)
    m:cycle(n)
    steps = steps + n
    local ft, fb = 0, 0
    for _, b in ipairs(top) do ft = ft - b.force[ax] end
    for _, b in ipairs(bottom) do fb = fb + b.force[ax] end
    local strain = (top[1].pos[ax] - bottom[1].pos[ax] - y0) / h
    rows[#rows + 1] = {strain, ft / area, fb / area}
    if ft / area > peak then
      peak, at = ft / area, #rows
      rows[at].cracks = {tension = m:crack_count("tension") - t0, shear = m:crack_count("shear") - s0}
    end
    if ft / area < post_peak * peak and m:crack_count() > t0 + s0 then stopped = "post_peak"; break end
  end
  m:close()
  if not at then error("joints.direct_tension: the specimen never carried a pull", 2) end
  if opts.log then
    opts.log(string.format("joints.direct_tension: peak %.4g MPa at strain %.3g, cracks %d tension / %d shear (%s)",
                           peak / 1e6, rows[at][1], rows[at].cracks.tension, rows[at].cracks.shear, stopped))
  end
  return {peak = peak, strain_at_peak = rows[at][1], cracks = rows[at].cracks, rows = rows, stopped = stopped}
end

--- The splitting strength of a Brazilian test (lab.brazilian's result r):
--- the tensile stress 2 F / (pi D t) at the first fall of the load by
--- `drop` (default 0.1) of its running maximum -- the disk's split, the
--- load a laboratory records -- or r's peak when the load never fell so.
--- A flat-jointed disk split in two goes on carrying load, its halves in
--- compression, to a later peak well above the split (docs/joints.md).
function joints.split_strength(r, drop)
  drop = drop or 0.1
  local col
  for k, name in ipairs(r.columns) do if name == "tensile_stress" then col = k end end
  local best = -math.huge
  for _, row in ipairs(r.rows) do
    local s = row[col]
    if s < (1 - drop) * best then return best end
    if s > best then best = s end
  end
  return r.tensile_strength
end

-- ------------------------------------------------------ jointed rock

local joint_keys = {angle = true, path = true, point = true, kn = true, ks = true, friction = true, dilation = true,
                    tension = true, cohesion = true, friction_angle = true, radius_multiplier = true}

-- The joint's parameters from opts, its stiffnesses by default the
-- specimen's bonds' (4-51, 4-52 at the mean pair: kn = Ec / (rmin + rmax)).
local function joint_def(spec, opts, point, normal)
  local b = spec.material.bond or {}
  local r = spec.radius
  local kn = opts.kn or (b.modulus or spec.material.modulus) / (r[1] + r[2])
  return {point = point, normal = normal, kn = kn, ks = opts.ks or kn / (b.stiffness_ratio or 2.5),
          friction = opts.friction or 0.5, dilation = opts.dilation, tension = opts.tension or opts.cohesion,
          cohesion = opts.cohesion, friction_angle = opts.friction_angle, radius_multiplier = opts.radius_multiplier}
end

-- the fields of a specimen that joints.jointed reads (check.lua's names)
local jointed_fields = {"path", "dim", "lo", "hi", "material", "radius"}

--- A jointed specimen: spec (lab.specimen's) with a smooth joint through
--- its centre (or `point`) whose normal makes `angle` degrees (beta) with
--- the loading axis (y in 2D, z in 3D; turned towards x), saved to `path`.
--- Bonds across the plane are cut, or replaced by the joint's bond when it
--- has a cohesion (and a tension, default the cohesion). opts: angle, path,
--- point, kn, ks (Pa/m; default the bonds'), friction (default 0.5),
--- dilation, tension, cohesion (Pa), friction_angle (degrees),
--- radius_multiplier. Returns the new spec, with spec.joint = {angle,
--- bonds (cut or replaced), contacts, def}.
function joints.jointed(spec, opts)
  check_keys("jointed", opts, joint_keys)
  if type(opts.angle) ~= "number" or opts.angle < 0 or opts.angle > 90 then
    error("joints.jointed: angle must be a number of degrees in [0, 90]", 2)
  end
  if type(opts.path) ~= "string" then error("joints.jointed: path (the jointed specimen's file) is required", 2) end
  c.specimen(spec, "jointed", jointed_fields)
  local dim = spec.dim
  local m = c.load(spec, "jointed")
  local point = opts.point
  if not point then
    point = {}
    for k = 1, dim do point[k] = 0.5 * (spec.lo[k] + spec.hi[k]) end
  end
  local beta = math.rad(opts.angle)
  local normal = dim == 2 and {math.sin(beta), math.cos(beta)} or {math.sin(beta), 0, math.cos(beta)}
  local def = joint_def(spec, opts, point, normal)
  local _, bonds, contacts = m:joint(def)
  local out = merge(spec, {})
  out.path = opts.path
  out.bonds = m:bond_count()
  out.joint = {angle = opts.angle, bonds = bonds, contacts = contacts, def = def}
  m:vars().lab_specimen = merge(out, {})
  m:save(opts.path)
  m:close()
  return out
end

--- Jaeger's single plane of weakness: the axial stress sigma1 at which a
--- joint of cohesion cj and friction mu_j whose normal makes beta (degrees)
--- with sigma1 slips under the confining stress sigma3,
---   sigma1 = sigma3 + 2 (cj + mu_j sigma3) / ((1 - mu_j cot beta) sin 2 beta),
--- or nil where the joint cannot slip (beta <= phi_j or beta = 90).
function joints.jaeger(beta_deg, cj, muj, sigma3)
  sigma3 = sigma3 or 0
  local b = math.rad(beta_deg)
  local den = (1 - muj / math.tan(b)) * math.sin(2 * b)
  if not (den > 1e-12) then return nil end
  return sigma3 + 2 * (cj + muj * sigma3) / den
end

--- UCS of jointed specimens against the joint's angle: for each angle of
--- `angles` (degrees, default 0, 15, ..., 90) joints.jointed(spec, joint)
--- and lab.ucs, beside Jaeger's curve with the joint's cohesion and
--- tan(friction_angle), capped by the intact UCS (angle -1 in the rows).
--- opts: angles, joint (joints.jointed's options less angle and path),
--- test (lab.ucs's options), out (path prefix: out.csv, and out.png with
--- gnuplot), log. Returns {intact =, rows = {{angle, ucs, jaeger}, ...}}.
function joints.angle_series(spec, opts)
  c.log(opts.log, "angle_series")
  -- (those of lab.ucs and joints.jointed: all before the intact specimen's test)
  c.specimen(spec, "angle_series", {"path", "dim", "shape", "wall_kn", "material", "radius", "granular", "lo", "hi"})
  local angles = opts.angles or {0, 15, 30, 45, 52.5, 60, 67.5, 75, 90}
  if opts.out ~= nil then c.prefix(opts.out, "angle_series") end
  local out = opts.out or "angle_series"
  local joint = opts.joint or {}
  local test = merge(opts.test or {}, {log = opts.log})
  local intact = lab.ucs(spec, test).peak
  local cj, muj = joint.cohesion or 0, math.tan(math.rad(joint.friction_angle or 0))
  local rows, csv = {}, {}
  for i, a in ipairs(angles) do
    local js = joints.jointed(spec, merge(joint, {angle = a, path = out .. "_" .. i .. ".h5"}))
    local peak = lab.ucs(js, test).peak
    local j = joints.jaeger(a, cj, muj)
    local theory = j and math.min(j, intact) or intact
    rows[i] = {angle = a, ucs = peak, jaeger = theory}
    csv[i] = {a, peak / 1e6, theory / 1e6, intact / 1e6}
    if opts.log then opts.log(string.format("joints.angle_series: beta %g deg: UCS %.4g MPa, Jaeger %.4g MPa", a,
                                            peak / 1e6, theory / 1e6)) end
  end
  lab.write_csv(out .. ".csv", {"angle_deg", "ucs_MPa", "jaeger_MPa", "intact_MPa"}, csv)
  return {intact = intact, rows = rows, cohesion = cj, friction = muj}
end

-- The joint contacts' resultant on the upper side (axis ax up): the normal
-- and shear stresses over the joint's length (2D) or area (3D), and the
-- count. A contact's force on b is fn N + fs, N from a's side to b's.
local function joint_stress(m, area, ax)
  local sn, tau, n = 0, 0, 0
  for c in m:contacts() do
    if c.joint then
      local up = c.normal[ax] > 0 and 1 or -1 -- b above the joint: the force on b is the upper side's
      sn = sn + up * (c.fn * c.normal[ax] + c.fs[ax])
      tau = tau - up * (c.fn * c.normal[1] + c.fs[1])
      n = n + 1
    end
  end
  return sn / area, tau / area, n
end

--- A direct-shear test of a joint: a horizontal smooth joint through the
--- middle of spec (a 2D rect or a 3D prism); the balls of the lowest
--- quarter held still, those of the highest quarter a grip that moves at
--- `speed` along +x while its vertical speed is servo-controlled to hold
--- the normal stress on the joint at `normal_stress` (the joint contacts'
--- normal forces over the joint's length or area). Records the joint's
--- shear and normal stress against the grip's shear displacement until
--- `displacement`. opts: normal_stress (Pa), joint (joints.jointed's
--- options less angle, path), speed (m/s, default 0.02), displacement
--- (default spec.radius[1]), every (steps, default 50), gain (default 0.2),
--- out (CSV prefix), log. Returns {peak, residual (the mean over the last
--- fifth), normal_stress, rows = {{disp, tau, sigma_n, dilation}, ...}}.
function joints.direct_shear(spec, opts)
  c.specimen(spec, "direct_shear", {"path", "dim", "shape", "lo", "hi", "material", "radius"})
  if opts.out ~= nil then c.prefix(opts.out, "direct_shear") end
  local dim = spec.dim
  if dim == 3 and spec.shape ~= "prism" or dim == 2 and spec.shape ~= "rect" then
    error("joints.direct_shear: a 2D rect or a 3D prism specimen", 2)
  end
  local sn = c.positive(opts.normal_stress, "normal_stress", "direct_shear")
  c.log(opts.log, "direct_shear")
  local every = c.steps(opts.every or 50, "every", "direct_shear")
  local js = joints.jointed(spec, merge(opts.joint or {}, {angle = 0, path = (opts.out or "direct_shear") .. ".h5"}))
  local m = seixo.load(js.path)
  local ax = dim
  local lo, hi = spec.lo[ax], spec.hi[ax]
  local h = hi - lo
  local area = (spec.hi[1] - spec.lo[1]) * (dim == 3 and (spec.hi[2] - spec.lo[2]) or 1)
  local grip = {}
  for b in m:balls() do
    local y = b.pos[ax]
    if y < lo + 0.25 * h then
      b.vel = dim == 3 and {0, 0, 0} or {0, 0}
      b.fix = "all"
    elseif y > hi - 0.25 * h then
      b.fix = "all"
      grip[#grip + 1] = b
    end
  end
  local speed = opts.speed or 0.02
  local gain = opts.gain or 0.2
  local target = opts.displacement or spec.radius[1]
  local dt = m:timestep()
  -- the grip's normal stiffness: the joint's contacts in series with the
  -- specimen, estimated from the joint's kn (the servo's gain scales it)
  local kj = js.joint.def.kn
  local function set_grip(vx, vy)
    for _, b in ipairs(grip) do b.vel = dim == 3 and {vx, 0, vy} or {vx, vy} end
  end
  local function servo(vx)
    local s = joint_stress(m, area, ax)
    -- vy = gain (s - sn) / (kj dt): a step of the stress error over the joint's stiffness per step
    local vy = gain * (s - sn) / (kj * every * dt)
    local cap = 10 * speed
    vy = math.max(-cap, math.min(cap, vy))
    set_grip(vx, vy)
    return s
  end
  -- the normal stress first
  local steps = 0
  repeat
    local s = servo(0)
    m:cycle(every)
    steps = steps + every
  until (math.abs(s - sn) < 0.01 * sn and steps > 20 * every) or steps > 200000
  local x0, y0 = grip[1].pos[1], grip[1].pos[ax]
  local rows, peak = {}, -math.huge
  while grip[1].pos[1] - x0 < target do
    servo(speed)
    m:cycle(every)
    local s, tau = joint_stress(m, area, ax)
    local d = grip[1].pos[1] - x0
    rows[#rows + 1] = {d, tau, s, grip[1].pos[ax] - y0}
    peak = math.max(peak, tau)
  end
  local n0 = math.floor(0.8 * #rows)
  local res, k = 0, 0
  for i = n0 + 1, #rows do res, k = res + rows[i][2], k + 1 end
  res = k > 0 and res / k or 0
  if opts.out then
    lab.write_csv(opts.out .. ".csv", {"shear_disp_m", "tau_Pa", "sigma_n_Pa", "normal_disp_m"}, rows)
  end
  if opts.log then
    opts.log(string.format("joints.direct_shear: sigma_n %.4g MPa: peak %.4g MPa, residual %.4g MPa (%d rows)",
                           sn / 1e6, peak / 1e6, res / 1e6, #rows))
  end
  m:close()
  return {peak = peak, residual = res, normal_stress = sn, rows = rows}
end

-- errors point at the caller's line, not into this file or lab.lua (seixo.caller)
require("seixo.caller").wrap(joints)

return joints
