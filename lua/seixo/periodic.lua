-- seixo.periodic: laboratory tests on a periodic cell, without walls
-- (PFC's periodic space, YADE's PeriTriaxController).
--   local periodic = require "seixo.periodic"       -- also lab.periodic
--   local spec = periodic.specimen{dim = 3, size = 0.01, path = "cell.h5"}
--   local r = periodic.triaxial(spec, {confining = 1e6})
--   local s = periodic.shear(spec, {normal = 1e6})
--
-- A specimen is a representative element: balls in a periodic cell, with
-- no wall anywhere, so no wall effect. Genesis: Potyondy & Cundall's, as
-- seixo.lab's specimen, with the cell held still for the vessel: radius
-- expansion, frictionless, then sigma0 (the mean direct stress) by scaling
-- every radius, the material's friction back, and the floaters moved and
-- grown until each has three neighbours within the bond gap (images across
-- the faces are neighbours); parallel bonds are installed between the
-- balls within the gap (bonds = false: a granular specimen), and the
-- cell's servo settles it at sigma0 on every axis. The tests drive the cell (m:cell_control):
-- a triaxial (or true-triaxial) test compresses the axial direction (z in 3D,
-- y in 2D) at a strain rate with the lateral stresses servo-controlled; a
-- simple shear tilts the cell at a shear rate with the normal stress (on y)
-- servo-controlled and the cell's other edges fixed.
--
-- Stresses are the cell's average stress (m:cell_stress), compression
-- positive, like seixo.lab's; strains are compression positive (a lateral
-- expansion is a negative lateral strain), volumetric strain 1 - V/V0, the
-- cell's change of volume (at small strains the axial plus (dim - 1)
-- lateral strains; at 25 % axial strain a dense sand's sum was -0.191 where
-- its volume had changed by -0.117). In 2D stresses are per unit thickness.

local periodic = {}

local check = require "seixo.check"
local c = check.module("periodic")
local fail, check_keys, check_writable, positive, steps, say = c.fail, c.keys, c.writable, c.positive, c.steps, c.say
local record_steps = check.record_steps

local names = {"xx", "yy", "zz"}

-- The cell's first n normal stress components servo-controlled to target
-- (a table per axis or one number), others as given in extra. The servo's
-- strain rate is bounded to 1e-5 per step: a step moves the images by at
-- most 1e-5 of the cell.
local function servo_all(m, n, target, extra)
  local c = {alpha = 0.5, max_rate = 1e-5 / m:timestep()}
  for k = 1, n do c[names[k]] = {stress = type(target) == "table" and target[k] or target} end
  for k, v in pairs(extra or {}) do c[k] = v end
  m:cell_control(c)
end

-- Cycles until every servo'd normal stress is within tol of its target and
-- the unbalanced-force ratio is below ratio; returns steps and the worst error.
local function settle(m, dim, target, tol, ratio, max_steps)
  local start, err = m:step(), math.huge
  repeat
    m:cycle(math.min(200, max_steps - (m:step() - start)))
    local s = m:cell_stress()
    err = 0
    for k = 1, dim do
      local t = type(target) == "table" and target[k] or target
      err = math.max(err, math.abs(s[k][k] / t - 1))
    end
  until (err < tol and m:ratio() < ratio) or m:step() - start >= max_steps
  return m:step() - start, err
end

--- A periodic specimen saved at opts.path; returns its table (periodic.open reads it back).
function periodic.specimen(opts)
  check_keys(opts, "specimen", {"dim", "size", "radius", "psd", "porosity", "material", "sigma0", "bonds", "gap", "seed",
                                "path", "log", "max_steps"})
  local lab = require "seixo.lab"
  local dim = opts.dim or 3
  if dim ~= 2 and dim ~= 3 then fail("periodic.specimen: dim must be 2 or 3 (got %s)", tostring(dim)) end
  local size = opts.size or 0.01
  if type(size) == "number" then size = dim == 3 and {size, size, size} or {size, size} end
  if type(size) ~= "table" or #size ~= dim then fail("periodic.specimen: size must be a length or %d lengths", dim) end
  for k = 1, dim do positive(size[k], "size", "specimen") end
  local radius, sizes = require("seixo.genesis").sizes(opts, "periodic.specimen", {0.4e-3, 0.66e-3})
  local mat = lab.rock(opts.material)
  local sigma0 = positive(opts.sigma0 or 0.1e6, "sigma0", "specimen")
  c.warn_stress(sigma0, "sigma0", "specimen")
  local porosity = opts.porosity or (dim == 3 and 0.35 or 0.16) -- seixo.lab's
  local seed = opts.seed or 1
  if opts.bonds ~= nil and type(opts.bonds) ~= "boolean" then
    fail("periodic.specimen: bonds must be true or false (false: a granular specimen; got %s)", tostring(opts.bonds))
  end
  local bonds = opts.bonds ~= false
  local path = opts.path or fail("periodic.specimen: a path for the specimen file is required")
  check_writable(path, "path", "specimen") -- before the genesis, not at its end
  local max_steps = steps(opts.max_steps or 50000, "max_steps", "specimen")
  local t0 = seixo.clock()

  local m = seixo.model{dim = dim}
  local frictionless = {} -- genesis is frictionless (a dense packing), as seixo.lab's
  for k, v in pairs(mat) do frictionless[k] = v end
  frictionless.friction = 0
  m:material("rock", frictionless)
  local lo = dim == 3 and {0, 0, 0} or {0, 0}
  m:periodic{min = lo, max = size}
  -- P&C's genesis, as seixo.lab's specimen: the expansion to a porosity
  -- below the one the packing jams at (it starts above sigma0 everywhere),
  -- then, the cell held still, sigma0 by radius scaling and the floaters
  -- grown (seixo.genesis)
  local n = m:generate{method = "expand", porosity = porosity, radius = sizes.radius, psd = sizes.psd,
                      region = {box = {lo, size}}, seed = seed, relax = false}
  say(opts, "periodic.specimen: %d balls by radius expansion to porosity %.3f in a periodic cell", n, porosity)
  local gap = opts.gap or 1e-3 * radius[1]
  local left, gen = require("seixo.genesis").periodic(m, mat, sigma0, gap, {max_steps = max_steps},
                                                      function(fmt, ...) say(opts, "periodic.specimen: " .. fmt, ...) end)
  local nb = 0
  if bonds then nb = m:bond{kind = "parallel", gap = gap, seed = seed} end
  -- the cell's servo then holds sigma0 on every axis (the radius scaling
  -- installs their mean)
  servo_all(m, dim, sigma0)
  local steps, err = settle(m, dim, sigma0, 0.01, 1e-2, max_steps)
  say(opts, "periodic.specimen: %d parallel bonds; settled at %.3g Pa within %.2f %% (%d steps)", nb, sigma0,
      100 * err, steps)
  local cell = m:periodic()
  local volume = 1
  for k = 1, dim do volume = volume * cell.size[k] end
  local spec = {path = path, dim = dim, size = cell.size, radius = radius, psd = opts.psd, balls = m:ball_count(),
                bonds = m:bond_count(), porosity = 1 - m:sum("volume") / volume, sigma0 = sigma0, material = mat,
                seed = seed, genesis_steps = m:step(), periodic = true,
                floaters_found = gen.floaters_found, floaters_left = left}
  m:vars().lab_specimen = spec -- lab.open's key: a specimen of either kind
  m:save(path) -- (with no clock time: the same genesis saves the same file)
  spec.genesis_time = seixo.clock() - t0
  say(opts, "periodic.specimen: %d balls, %d bonds, porosity %.3f, saved to %s (%.1f s)", spec.balls, spec.bonds,
      spec.porosity, path, spec.genesis_time)
  m:close()
  return spec
end

--- The periodic specimen saved at path (lab.open reads either kind).
function periodic.open(path) return require("seixo.lab").open(path) end

local function open_test(spec, fn)
  if type(spec) ~= "table" or not spec.periodic then fail("periodic.%s: a periodic specimen expected", fn) end
  c.specimen(spec, fn, {"path", "dim", "sigma0"})
  return c.load(spec, fn)
end

-- The secant modulus and Poisson's ratio at half the peak of column q,
-- interpolated between the rows that cross it (rows: ea, el, q).
local function half_peak(rows, peak_row, peak)
  local half = 0.5 * peak
  for i = 1, peak_row do
    if rows[i].q >= half then
      local a = rows[i - 1] or {ea = 0, el = 0, q = 0}
      local b = rows[i]
      local t = (b.q - a.q) > 0 and (half - a.q) / (b.q - a.q) or 1
      local ea, el = a.ea + t * (b.ea - a.ea), a.el + t * (b.el - a.el)
      return half / ea, -el / ea
    end
  end
end

-- The loading's mean unbalanced-force ratio over its records, and the
-- quasi-static warnings it raises (a sand user's loading at 20/s read a
-- Poisson's ratio of 3.9 with no word: the walled tests warned).
local function mean_ratio(rows)
  local sum, n = 0, 0
  for _, row in ipairs(rows) do
    if row.ratio < math.huge then sum, n = sum + row.ratio, n + 1 end -- (no contact force yet: no ratio)
  end
  local mean = n > 0 and sum / n or 0
  return mean, check.balance_warnings(mean)
end

--- A triaxial test of a periodic cell: the lateral stresses held at
--- confining (and intermediate on x, 3D), the axial direction compressed at
--- strain_rate (1/s) up to max_strain or past the peak (post_peak).
function periodic.triaxial(spec, opts)
  opts = opts or {}
  check_keys(opts, "triaxial", {"confining", "intermediate", "strain_rate", "max_strain", "post_peak", "every", "log",
                                "max_steps"})
  local m = open_test(spec, "triaxial")
  local dim = spec.dim
  local ax = dim
  local sigma3 = positive(opts.confining or spec.sigma0, "confining", "triaxial")
  local sigma2 = positive(opts.intermediate or sigma3, "intermediate", "triaxial")
  -- (the cell's servo, unlike a wall's, does not warn of its target)
  c.warn_stress(sigma3, "confining", "triaxial")
  if opts.intermediate then c.warn_stress(sigma2, "intermediate", "triaxial") end
  if dim == 2 and sigma2 ~= sigma3 then fail("periodic.triaxial: an intermediate stress needs a 3D cell") end
  local max_strain = positive(opts.max_strain or 0.02, "max_strain", "triaxial")
  local post_peak = c.number(opts.post_peak or 0.7, "post_peak", "triaxial", "in (0, 1)",
                             function(v) return v > 0 and v < 1 end)
  local every = steps(opts.every or 100, "every", "triaxial")
  local max_steps = steps(opts.max_steps or 1000000, "max_steps", "triaxial")
  local rate = opts.strain_rate or 7e-8 / m:timestep() -- seixo.lab's quasi-static default
  positive(rate, "strain_rate", "triaxial")
  local t0 = seixo.clock()
  local lateral = {}
  for k = 1, dim - 1 do lateral[k] = (k == 1 and dim == 3) and sigma2 or sigma3 end
  lateral[ax] = sigma3
  servo_all(m, dim, lateral)
  local confine_steps = settle(m, dim, lateral, 0.01, 1e-2, opts.max_steps or 100000)
  -- loading: the axial edge shortens at the rate, the lateral servos hold
  local extra = {[names[ax]] = {rate = -rate}}
  servo_all(m, dim - 1, lateral, extra)
  local L0 = m:periodic().size
  local rows, peak, peak_row, start, why = {}, -math.huge, nil, m:step(), "max_strain"
  local ea = 0
  while true do
    m:cycle(record_steps(every, max_steps - (m:step() - start), max_strain - ea, rate * m:timestep()))
    local L, s = m:periodic().size, m:cell_stress()
    local el, sl = 0, 0
    ea = (L0[ax] - L[ax]) / L0[ax]
    for k = 1, dim - 1 do
      el = el + (L0[k] - L[k]) / L0[k] / (dim - 1)
      sl = sl + s[k][k] / (dim - 1)
    end
    local volume = 1 -- the cell's volume over its first (the tilts are held at zero)
    for k = 1, dim do volume = volume * L[k] / L0[k] end
    local row = {step = m:step() - start, ea = ea, el = el, ev = 1 - volume, sa = s[ax][ax], sl = sl,
                 q = s[ax][ax] - sigma3, ratio = m:ratio(), cracks = m:crack_count()}
    rows[#rows + 1] = row
    if row.q > peak then peak, peak_row = row.q, #rows end
    if peak > 0 and row.q < post_peak * peak and ea > rows[peak_row].ea then why = "post_peak"; break end
    if ea >= max_strain then break end
    if m:step() - start >= max_steps then why = "max_steps"; break end
  end
  local r = {kind = "periodic triaxial", dim = dim, confining = sigma3, intermediate = sigma2, rows = rows,
             stopped = why, strain_rate = rate, steps = m:step() - start, confine_steps = confine_steps,
             peak_deviator = peak, peak = peak + sigma3, peak_strain = rows[peak_row].ea}
  r.young, r.poisson = half_peak(rows, peak_row, peak)
  r.wall_time = seixo.clock() - t0
  r.mean_ratio, r.warnings = mean_ratio(rows)
  for _, w in ipairs(r.warnings) do say(opts, "periodic.triaxial: warning: %s", w) end
  say(opts, "periodic.triaxial: sigma3 %.4g MPa: peak %.4g MPa at strain %.4g, E %.4g GPa, nu %.3f (%d steps, %.1f s)",
      sigma3 / 1e6, r.peak / 1e6, r.peak_strain, (r.young or 0) / 1e9, r.poisson or 0, r.steps, r.wall_time)
  m:close()
  return r
end

--- Simple shear of a periodic cell at constant normal stress: the cell
--- tilts (x over y) at shear_rate (1/s) up to max_strain, its y edge
--- servo-controlled to normal, the other edges fixed. rows hold the shear
--- strain gamma, the shear stress tau (on the x faces, positive along the
--- shear), the normal stress and the volumetric strain.
function periodic.shear(spec, opts)
  opts = opts or {}
  check_keys(opts, "shear", {"normal", "shear_rate", "max_strain", "every", "log", "max_steps"})
  local m = open_test(spec, "shear")
  local dim = spec.dim
  local normal = positive(opts.normal or spec.sigma0, "normal", "shear")
  c.warn_stress(normal, "normal", "shear")
  local max_strain = positive(opts.max_strain or 0.05, "max_strain", "shear")
  local rate = opts.shear_rate or 7e-8 / m:timestep()
  positive(rate, "shear_rate", "shear")
  local every = steps(opts.every or 100, "every", "shear")
  local t0 = seixo.clock()
  servo_all(m, dim, normal)
  local max_steps = opts.max_steps and steps(opts.max_steps, "max_steps", "shear")
  local confine_steps = settle(m, dim, normal, 0.01, 1e-2, max_steps or 100000)
  local start, why = m:step(), "max_strain"
  servo_all(m, 0, nil, {yy = {stress = normal}, xy = {rate = rate}})
  local L0 = m:periodic().size
  local rows, peak, gamma = {}, -math.huge, 0
  repeat
    m:cycle(record_steps(every, (max_steps or 1000000) - (m:step() - start), max_strain - gamma, rate * m:timestep()))
    local cell, s = m:periodic(), m:cell_stress()
    local row = {step = m:step() - start, gamma = cell.tilt.xy / cell.size[2], tau = -s[1][2], sn = s[2][2],
                 ev = (L0[2] - cell.size[2]) / L0[2], ratio = m:ratio()}
    rows[#rows + 1] = row
    gamma = row.gamma
    peak = math.max(peak, row.tau / row.sn)
    if row.gamma < max_strain and m:step() - start >= (max_steps or 1000000) then why = "max_steps"; break end
  until row.gamma >= max_strain
  local ratio, warnings = mean_ratio(rows)
  for _, w in ipairs(warnings) do say(opts, "periodic.shear: warning: %s", w) end
  local r = {kind = "periodic shear", dim = dim, normal = normal, rows = rows, steps = m:step() - start, stopped = why,
             mean_ratio = ratio, warnings = warnings,
             confine_steps = confine_steps,
             peak_ratio = peak, friction_angle = math.deg(math.atan(peak)), wall_time = seixo.clock() - t0}
  say(opts, "periodic.shear: normal %.4g MPa: peak tau/sigma %.3f (%.1f deg), dilation %.4g (%.1f s)", normal / 1e6,
      peak, r.friction_angle, -rows[#rows].ev, r.wall_time)
  m:close()
  return r
end

-- errors point at the caller's line, not into this file (seixo.caller)
require("seixo.caller").wrap(periodic)

return periodic
