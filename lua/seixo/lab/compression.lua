-- seixo.lab.compression: the compression tests of a walled specimen
-- (lab.ucs, lab.triaxial): its confinement by servo-controlled walls, the
-- axial loading under PFC's loading-rate control, and the peak, moduli
-- and warnings read from the records.
local seixo = require "seixo"  -- a global in the executable, not under a stock lua5.4
local check = require "seixo.check"
local tables = require "seixo.lab.tables"
local csv = require "seixo.lab.csv"
local frame = require "seixo.lab.frame"
local strain = require "seixo.lab.strain"
local plots = require "seixo.lab.plots"
local compression = {}

local pi = math.pi
local c = check.module("lab")
local fail, check_keys, positive, steps, say = c.fail, c.keys, c.positive, c.steps, c.say
local stress, number, record_steps = c.stress, c.number, check.record_steps
local copy = tables.copy
local check_spec, axis_of, default_rate, inertial_number = frame.check_spec, frame.axis_of, frame.default_rate,
                                                            frame.inertial_number
local check_out_and_scale, open_test, drive, finish, few_records = frame.check_out_and_scale, frame.open, frame.drive,
                                                                   frame.finish, frame.few_records

-- the fields of a specimen the compression tests read (frame.check_spec)
local compression_fields = {"path", "dim", "shape", "wall_kn", "material", "radius", "granular"}

local test_keys = {"confining", "intermediate", "strain_rate", "max_strain", "post_peak", "every", "out", "plot", "log",
                   "lateral", "max_steps", "confine_tol", "name", "target_ratio", "max_rate", "density_scale"}

local columns = {"step", "time", "axial_strain", "lateral_strain", "volumetric_strain", "axial_stress",
                 "lateral_stress", "deviator", "cracks_tension", "cracks_shear", "ratio", "inertial", "strain_rate"}

-- A test stopped while loading (Ctrl-C, a SIGTERM, an error): with
-- opts.out its records so far go to out.csv, which the message names,
-- before the error goes on (they were lost with the test).
local function keep_records(err, opts, rows)
  if opts.out and #rows > 0 and pcall(csv.write, opts.out .. ".csv", columns, rows) then
    err = string.format("%s (the test's %d records so far are in %s.csv)", tostring(err), #rows, opts.out)
  end
  error(err, 0)
end

-- The loading-rate control's options: the unbalanced-force ratio it keeps
-- the loading under (false: a constant strain rate) and the fastest rate.
local function rate_control(opts, rate, fn)
  local target = opts.target_ratio
  if target == nil then target = 2e-3 end
  if target == false then
    if opts.max_rate then fail("lab.%s: max_rate is the rate control's; target_ratio = false turns it off", fn) end
    return nil, rate
  end
  number(target, "target_ratio", fn, "a ratio in (0, 1) or false", function(v) return v > 0 and v < 1 end)
  local max_rate = number(opts.max_rate or 8 * rate, "max_rate", fn,
                          string.format("a strain rate >= strain_rate = %g 1/s", rate),
                          function(v) return v >= rate and v < math.huge end)
  return target, max_rate
end

-- PFC's loading-rate control by the mean unbalanced-force ratio, and the
-- cracks: while the ratio stays below half its target and no bond breaks
-- the platens speed up by 15 % a record, up to max_factor times
-- strain_rate; when it exceeds the target or a bond breaks they halve
-- their speed, down to strain_rate. A bonded specimen's ratio under a
-- steady load falls as its stress grows (the unbalanced forces the platens'
-- motion causes stay, the contact forces grow), so the ratio lets the
-- loading speed up while the specimen is elastic; the peak, which moves
-- with the rate (+2.6 % at twice it on the main job's UCS), is reached by
-- cracking, and there the cracks hold the loading near strain_rate: the
-- ratio alone, noisy (a factor of 2 to 3 between records) and lifted by
-- each change of speed, cannot tell that phase apart without a target so
-- low that it never speeds up (docs/performance.md, Lab throughput). The
-- target 2e-3: on the main job's specimen with lab.rock{dim = 3} the UCS
-- peaked at 209.3 MPa at 4e-3, 3.8 % below the constant half rate's 217.7
-- (at 2e-3: 215.6, and 217.7 at half the rate and target); on lab.rock()'s
-- specimen 8e-3 already failed the quasi-static check (docs/performance.md).
-- (Measured before the ratio counted the bonds' forces, stop 35, which
-- about halved a bonded specimen's ratio; the peaks did not move with the
-- target then: docs/performance.md.)
local function rate_factor(factor, ratio, cracked, target, max_factor)
  if ratio > target or cracked then return math.max(1, 0.5 * factor) end
  if ratio < 0.5 * target then return math.min(max_factor, 1.15 * factor) end
  return factor
end

-- The options of a compression test, checked before it starts, in the
-- name of fn, the function the user called (lab.series checks its tests'
-- so, before the first). Returns sigma3, sigma2, max_strain, post_peak
-- and every.
local function test_options(spec, opts, fn)
  check_keys(opts, fn, test_keys)
  local dim = spec.dim
  if spec.shape == "disc" or spec.shape == "disk" then
    fail("lab.%s: a %s specimen is for the Brazilian test; make a %s", fn, spec.shape,
         dim == 3 and "cylinder or prism" or "rect")
  end
  local sigma3 = stress(opts.confining or 0, "confining", fn)
  -- a true triaxial test of a prism: sigma2 on the x faces, sigma3 on the y faces
  local sigma2 = number(opts.intermediate or sigma3, "intermediate", fn, "a stress >= confining",
                        function(v) return v >= sigma3 and v < math.huge end)
  if sigma2 ~= sigma3 and not (dim == 3 and spec.shape == "prism") then
    fail("lab.%s: an intermediate stress needs a 3D prism (six planes)", fn)
  end
  if sigma2 ~= sigma3 and sigma3 == 0 then
    fail("lab.%s: an intermediate stress needs confining > 0 (without it the test has no lateral walls)", fn)
  end
  if spec.granular and sigma3 == 0 then
    fail("lab.%s: a granular specimen needs confining > 0: without bonds nothing holds it together", fn)
  end
  if opts.lateral ~= nil and opts.lateral ~= "planes" and opts.lateral ~= "cylinder" then
    fail("lab.%s: lateral must be \"cylinder\" or \"planes\" (got %s)", fn, tostring(opts.lateral))
  end
  if opts.lateral == "cylinder" and not (dim == 3 and spec.shape == "cylinder") then
    fail("lab.%s: lateral = \"cylinder\" needs a 3D cylinder (this specimen is a %dD %s)", fn, dim, spec.shape)
  end
  if opts.strain_rate ~= nil then positive(opts.strain_rate, "strain_rate", fn) end
  local max_strain = positive(opts.max_strain or 0.02, "max_strain", fn)
  local post_peak = number(opts.post_peak or 0.7, "post_peak", fn, "in (0, 1)", function(v) return v > 0 and v < 1 end)
  local every = steps(opts.every or 100, "every", fn)
  if opts.max_steps ~= nil then steps(opts.max_steps, "max_steps", fn) end
  if opts.name ~= nil and type(opts.name) ~= "string" then
    fail("lab.%s: name must be a string, the test's label (got %s)", fn, check.got(opts.name))
  end
  check_out_and_scale(opts, fn)
  return sigma3, sigma2, max_strain, post_peak, every
end

-- A triaxial (confining > 0) or unconfined compression test.
local function run(spec, opts, fn)
  check_spec(spec, fn, compression_fields)
  local sigma3, sigma2, max_strain, post_peak, every = test_options(spec, opts, fn)
  local dim, ax = spec.dim, axis_of(spec.dim)
  local t0 = seixo.clock()

  local m, lo, hi, centre, bottom, top = open_test(spec, opts, fn)
  local rate = opts.strain_rate or default_rate(m)
  local control, max_rate = rate_control(opts, rate, fn)
  local kn, fr, kind = spec.wall_kn, 0, dim == 3 and "plane" or "line"

  -- lateral confinement: a cylinder or planes (lines), servo-controlled
  local lateral = {}
  local use_cylinder = sigma3 > 0 and dim == 3 and spec.shape == "cylinder" and opts.lateral ~= "planes"
  if sigma3 > 0 then
    if use_cylinder then
      local rmax = 0
      for b in m:balls() do
        local p = b.pos
        rmax = math.max(rmax, math.sqrt((p[1] - centre[1]) ^ 2 + (p[2] - centre[2]) ^ 2) + b.radius)
      end
      local cpoint = copy(centre)
      cpoint[3] = 0
      lateral[1] = m:wall{kind = "cylinder", point = cpoint, axis = {0, 0, 1}, radius = rmax, height = 0, kn = kn,
                          ks = 0, friction = fr}
    else
      for k = 1, dim do
        if k ~= ax then
          local n1, n2, q1, q2 = {}, {}, copy(centre), copy(centre)
          for j = 1, dim do n1[j], n2[j] = 0, 0 end
          n1[k], n2[k] = 1, -1
          q1[k], q2[k] = lo[k], hi[k]
          lateral[#lateral + 1] = m:wall{kind = kind, point = q1, normal = n1, kn = kn, ks = 0, friction = fr}
          lateral[#lateral + 1] = m:wall{kind = kind, point = q2, normal = n2, kn = kn, ks = 0, friction = fr}
        end
      end
    end
  end

  -- geometry of the moment: length, cross-section area, lateral areas
  local function height() return top.point[ax] - bottom.point[ax] end
  local function lateral_extent(k) -- the distance between the two walls normal to k
    for i = 1, #lateral, 2 do
      if lateral[i].normal[k] == 1 then return lateral[i + 1].point[k] - lateral[i].point[k] end
    end
  end
  local width0 = {}
  for k = 1, dim do width0[k] = hi[k] - lo[k] end
  local function section()
    if use_cylinder then return pi * lateral[1]:radius() ^ 2 end
    if spec.shape == "cylinder" then return pi * (0.25 * (width0[1] + width0[2])) ^ 2 end
    local a = 1
    for k = 1, dim do if k ~= ax then a = a * (lateral_extent(k) or width0[k]) end end
    return a
  end
  local function lateral_areas() -- per lateral wall
    local h, areas = height(), {}
    if use_cylinder then return {2 * pi * lateral[1]:radius() * h} end
    for i = 1, #lateral do
      local k
      for j = 1, dim do if lateral[i].normal[j] ~= 0 then k = j end end
      local a = h
      for j = 1, dim do if j ~= k and j ~= ax then a = a * lateral_extent(j) end end
      areas[i] = a
    end
    return areas
  end
  local function target_of(w) return w.kind ~= "cylinder" and w.normal[1] ~= 0 and sigma2 or sigma3 end
  -- the lateral walls' speed limit: 0.05 m/s while confining; when loading,
  -- see lateral_limit below
  local lateral_limit = 0.05
  local function servo_lateral()
    local areas = lateral_areas()
    for i, w in ipairs(lateral) do
      w:servo{target = target_of(w), area = areas[i], alpha = 0.5, max_speed = lateral_limit}
    end
  end
  -- the minor principal stress: the mean over the walls held at sigma3
  local function lateral_stress()
    local areas, s, n = lateral_areas(), 0, 0
    for i, w in ipairs(lateral) do
      if target_of(w) == sigma3 then s, n = s + w:load() / areas[i], n + 1 end
    end
    return n > 0 and s / n or 0
  end
  local function lateral_error() -- the worst relative error of the lateral walls
    local areas, worst = lateral_areas(), 0
    for i, w in ipairs(lateral) do worst = math.max(worst, math.abs(w:load() / areas[i] / target_of(w) - 1)) end
    return worst
  end
  local function axial_stress() return 0.5 * (top:load() + bottom:load()) / section() end

  -- confinement: all walls servo-controlled to sigma3, then held there
  local confine_steps = 0
  if sigma3 > 0 then
    local start, tol = m:step(), opts.confine_tol or 0.01
    local budget = (opts.max_steps or 400000) / 4
    repeat
      servo_lateral()
      local s = section()
      top:servo{target = sigma2, area = s, alpha = 0.5, max_speed = 0.05}
      bottom:servo{target = sigma2, area = s, alpha = 0.5, max_speed = 0.05}
      m:cycle(math.min(200, math.ceil(budget - (m:step() - start))))
      local ok = math.abs(axial_stress() / sigma2 - 1) < tol and lateral_error() < tol
    until (ok and m:ratio() < 1e-3) or m:step() - start >= budget
    confine_steps = m:step() - start
    top:servo(nil)
    bottom:servo(nil)
    say(opts, "lab.%s: confined at %.4g Pa in %d steps (axial %.4g, lateral %.4g Pa)", fn, sigma3, confine_steps,
        axial_stress(), lateral_stress())
  end

  -- axial loading at a constant strain rate, both platens moving
  local h0 = height()
  local speed = 0.5 * rate * h0
  -- past the peak a dilating specimen pushes the lateral walls out at up to
  -- 2.5 times the axial strain rate (a 2D specimen of clumps): at 0.05 m/s
  -- they fell behind and sigma3 rose thirteenfold (6 times for balls in
  -- 2D), a confinement the test no longer controls. Ten times the platens'
  -- speed leaves room for that dilation on specimens up to twice as wide as
  -- high; before the peak the walls move far slower than either limit.
  -- the rate control: the platens speed up to max_rate while the ratio is
  -- low and slow down to strain_rate when it is high (see rate_factor)
  local top_speed = control and 0.5 * max_rate * h0 or speed
  lateral_limit = math.max(0.05, 10 * top_speed)
  drive(top, bottom, dim, speed)
  local factor = 1
  -- The lateral strain from the balls in every test, confined or not: the
  -- walls ride on the surface layer, looser than the core, and give a
  -- confined test's nu far from the bulk's (3D, sigma3 0.1 / 10 MPa: 0.391 /
  -- 0.196 from the cylinder against 0.243 from the balls; docs/potyondy-cundall.md).
  local lateral_strain = strain.lateral(m, ax)

  local rows, peak, peak_row = {}, -math.huge, nil
  local start, t_start = m:step(), m:time()
  local cracks0 = {m:crack_count("tension"), m:crack_count("shear")}
  local max_steps = opts.max_steps or 400000
  local ratio_sum, ratio_n, inertial_max = 0, 0, 0
  local why = "max_strain"
  local ea = 0
  local loaded, err = pcall(function()
    while true do
      if #lateral > 0 then servo_lateral() end
      local n = record_steps(every, max_steps - (m:step() - start), max_strain - ea, rate * factor * m:timestep())
      -- the ratio: the mean of four readings over the interval (one reading
      -- swings by a factor of 3 with the specimen's vibrations)
      local ratio, readings = 0, math.min(4, n)
      for i = 1, readings do
        m:cycle(n // readings + (i <= n % readings and 1 or 0))
        ratio = ratio + m:ratio() / readings
      end
      ea = (h0 - height()) / h0
      local el = lateral_strain()
      local sa, sl = axial_stress(), lateral_stress()
      local q = sa - sl
      local p = (sa + (dim - 1) * sl) / dim
      local inertial = inertial_number(rate * factor, spec, p, opts.density_scale or 1)
      if m:step() - start > 10 * every then -- past the first contact transients
        ratio_sum, ratio_n = ratio_sum + ratio, ratio_n + 1
        if inertial < math.huge then inertial_max = math.max(inertial_max, inertial) end
      end
      local row = {m:step() - start, m:time() - t_start, ea, el, 1 - (1 - ea) * (1 - el) ^ (dim - 1), sa, sl, q,
                   m:crack_count("tension") - cracks0[1], m:crack_count("shear") - cracks0[2], ratio, inertial,
                   rate * factor}
      rows[#rows + 1] = row
      if control then
        local cracked = row[9] + row[10] > (rows[#rows - 1] and rows[#rows - 1][9] + rows[#rows - 1][10] or 0)
        local f = rate_factor(factor, ratio, cracked, control, max_rate / rate)
        if f ~= factor then factor = f; drive(top, bottom, dim, speed * factor) end
      end
      if q > peak then peak, peak_row = q, #rows end
      -- past the peak: a bonded specimen loses strength only by cracking, so
      -- a drop without cracks is a transient (the platens seating)
      if peak > 0 and q < post_peak * peak and ea > rows[peak_row][3] and row[9] + row[10] > 0 then
        why = "post_peak"
        break
      end
      if ea >= max_strain then break end
      if m:step() - start >= max_steps then why = "max_steps"; break end
    end
  end)
  if not loaded then keep_records(err, opts, rows) end

  -- results: peak, secant modulus and Poisson's ratio at half the peak
  local r = {kind = sigma3 > 0 and "triaxial" or "ucs", confining = sigma3, intermediate = sigma2, dim = dim,
             rows = rows,
             columns = columns, stopped = why, steps = m:step() - start, confine_steps = confine_steps,
             strain_rate = rate, platen_speed = speed, target_ratio = control or false, max_rate = max_rate,
             density_scale = opts.density_scale or 1, timestep = m:timestep(), name = opts.name}
  local pr = rows[peak_row]
  r.peak_deviator = peak
  r.peak = peak + sigma3            -- sigma1 at failure
  r.peak_strain = pr[3]
  -- the loading starts from the deviator of the confinement, sigma2 -
  -- sigma3 (a true-triaxial test's platens are held at sigma2, so its
  -- deviator is 10 MPa at zero strain for sigma2 - sigma3 = 10 MPa): the
  -- secant is that of the loading, over the deviator's rise to half its rise
  -- to the peak (for a conventional test, from zero to half the peak)
  local q0 = sigma2 - sigma3
  local half = q0 + 0.5 * (peak - q0)
  for i = 1, peak_row do
    if rows[i][8] >= half then
      local a = rows[i - 1] or {0, 0, 0, 0, 0, 0, 0, q0}
      local b = rows[i]
      local t = (b[8] - a[8]) > 0 and (half - a[8]) / (b[8] - a[8]) or 1
      local ea = a[3] + t * (b[3] - a[3])
      local el = a[4] + t * (b[4] - a[4])
      r.young = (half - q0) / ea
      r.poisson = -el / ea
      break
    end
  end
  r.cracks = {tension = pr[9], shear = pr[10]}
  r.cracks_total = {tension = rows[#rows][9], shear = rows[#rows][10]}
  r.mean_ratio = ratio_n > 0 and ratio_sum / ratio_n or m:ratio()
  r.inertial = inertial_max
  r.wall_time = seixo.clock() - t0
  r.warnings = check.balance_warnings(r.mean_ratio, r.inertial)
  -- the confinement the walls held at the peak: a servo that lags the
  -- loading (a stiff material loaded fast) confines more than sigma3, and
  -- the peak and a fit with it are off (a sand at 0.1 MPa was held at 0.18:
  -- a first-day user's finding)
  if sigma3 > 0 then
    r.lateral_at_peak = pr[7]
    if math.abs(pr[7] / sigma3 - 1) > 0.05 then
      r.warnings[#r.warnings + 1] = string.format("the lateral walls held %.4g MPa at the peak, %+.0f %% from sigma3 "
        .. "%.4g MPa: their servo lags the loading; lower strain_rate (or max_rate)", pr[7] / 1e6,
        100 * (pr[7] / sigma3 - 1), sigma3 / 1e6)
    end
  end
  if why == "max_steps" or (why ~= "post_peak" and not spec.granular) then -- (a sand is loaded to max_strain)
    r.warnings[#r.warnings + 1] = string.format("stopped on %s before the stress fell past the peak", why)
  end
  few_records(r, every)
  for _, w in ipairs(r.warnings) do say(opts, "lab.%s: warning: %s", fn, w) end
  say(opts, "lab.%s: sigma3 %.4g MPa: peak %.4g MPa at strain %.4g, E %.4g GPa, nu %.3f, cracks %d tension / %d shear "
      .. "(%d steps, %.1f s; ratio %.2g, inertial number %.2g)", fn, sigma3 / 1e6, r.peak / 1e6, r.peak_strain,
      (r.young or 0) / 1e9, r.poisson or 0, r.cracks.tension, r.cracks.shear, r.steps, r.wall_time, r.mean_ratio,
      r.inertial)

  return finish(m, r, opts, plots.test)
end

--- A triaxial test (confining = sigma3 > 0, by servo-controlled walls) or,
--- with confining = 0, an unconfined compression test.
function compression.triaxial(spec, opts) return run(spec, opts or {}, "triaxial") end

--- The unconfined (uniaxial) compression test: no lateral walls.
function compression.ucs(spec, opts)
  opts = copy(opts or {})
  if opts.confining and opts.confining ~= 0 then fail("lab.ucs: the UCS test has no confining stress") end
  opts.confining = 0
  return run(spec, opts, "ucs")
end

-- (a series checks its tests' specimen and options as they will)
compression.fields, compression.keys, compression.options, compression.rate_control = compression_fields, test_keys,
                                                                                        test_options, rate_control

return compression
