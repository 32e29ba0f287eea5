-- seixo.lab.specimen: a bonded specimen's genesis (lab.specimen), saved
-- to its file, and the specimen a file holds (lab.open).
--
-- Specimen genesis follows Potyondy & Cundall (2004, "material genesis"):
-- a polydisperse assembly is made by radius expansion in a vessel of walls,
-- frictionless, to a porosity below the jammed one; the radii are scaled
-- down until the walls carry a small isotropic stress (with the rock's
-- friction for the last part); the floaters are moved and grown until each
-- has three neighbours; parallel bonds are installed between the touching
-- balls (the BPM micro-parameters of the material, seed 4.4); the vessel is
-- removed and the specimen relaxes, which reduces the locked-in stresses;
-- the specimen is trimmed to its shape (a cylinder, a prism, a disk) and
-- saved. Every test starts from that file. A specimen of clumps cannot
-- grow: its clumps are placed at random in a larger vessel that closes in
-- with them until they jam, the servo decompresses them to the isotropic
-- stress, and the friction comes back before the last servo (see
-- compact_clumps and lab.specimen).

local seixo = require "seixo"  -- a global in the executable, not under a stock lua5.4
local genesis = require "seixo.genesis"
local check = require "seixo.check"
local tables = require "seixo.lab.tables"
local material = require "seixo.lab.material"
local vessel = require "seixo.lab.vessel"
local polling = require "seixo.lab.polling"
local specimen = {}

local pi = math.pi
local c = check.module("lab")
local fail, check_keys, check_writable, positive, say = c.fail, c.keys, c.writable, c.positive, c.say
local copy, merge = tables.copy, tables.merge
local ball_kn = material.ball_kn
local make_vessel, servo_vessel, solid_volume, compact_clumps = vessel.make, vessel.servo, vessel.solid_volume,
                                                              vessel.compact_clumps

-- The balls' bounding box including their radii.
function specimen.extents(m)
  local dim = m:dim()
  local lo, hi = {}, {}
  for k = 1, dim do lo[k], hi[k] = math.huge, -math.huge end
  for b in m:balls() do
    local p, r = b.pos, b.radius
    for k = 1, dim do
      if p[k] - r < lo[k] then lo[k] = p[k] - r end
      if p[k] + r > hi[k] then hi[k] = p[k] + r end
    end
  end
  return lo, hi
end
local extents = specimen.extents

local shapes = check.shapes

-- The box a shape fills, the axis of its cylindrical vessel (3D cylinder:
-- z; disc: y), and for a 2D disk the circle it is trimmed to.
local function shape_of(opts, dim)
  local shape = opts.shape
  if dim == 3 and shape == "cylinder" then
    local d, h = positive(opts.diameter, "diameter", "specimen"), positive(opts.height, "height", "specimen")
    return {d, d, h}, 3
  elseif dim == 3 and shape == "disc" then -- a Brazilian disc: axis along y, loaded along z
    local d, t = positive(opts.diameter, "diameter", "specimen"), positive(opts.thickness, "thickness", "specimen")
    return {d, t, d}, 2
  elseif dim == 3 and shape == "prism" then
    local w, h = positive(opts.width, "width", "specimen"), positive(opts.height, "height", "specimen")
    return {w, opts.depth and positive(opts.depth, "depth", "specimen") or w, h}
  elseif dim == 2 and shape == "rect" then
    return {positive(opts.width, "width", "specimen"), positive(opts.height, "height", "specimen")}
  elseif dim == 2 and shape == "disk" then
    local d = positive(opts.diameter, "diameter", "specimen")
    return {d, d}, nil, {center = {d / 2, d / 2}, radius = d / 2}
  end
end

-- The specimen's core, where the genesis measures its stress (its box
-- less two largest radii from every side), must hold balls: every
-- half-size (across a 3D cylinder or disc, the inscribed square's) at
-- least 2.5 largest radii rmax. Fails (at the caller's caller) if not.
local function check_size(size, cyl_axis, rmax)
  for k = 1, #size do
    local need = 5 * rmax * (cyl_axis and k ~= cyl_axis and math.sqrt(2) or 1)
    if size[k] < need then
      error(string.format("lab.specimen: the balls are too large for the specimen: its size along %s is %g m, less "
                          .. "than the %g m that its largest radius %g m needs; make the balls smaller or the "
                          .. "specimen larger", ({"x", "y", "z"})[k], size[k], need, rmax), 3)
    end
  end
end

--- Makes a bonded specimen (material genesis) and saves it to opts.path.
--- Returns a specimen table for the tests: {path, dim, shape, size, balls,
--- bonds, porosity, floaters, sigma0, material, ...}.
function specimen.make(opts)
  check_keys(opts, "specimen", {"dim", "shape", "diameter", "height", "width", "depth", "thickness", "radius", "psd",
                                "porosity", "material", "sigma0", "sigma0_tol", "floater_contacts", "gap", "gapped", "seed", "path",
                                "log", "max_steps", "clump", "model", "bonds"})
  local dim = opts.dim or 3
  if dim ~= 2 and dim ~= 3 then fail("lab.specimen: dim must be 2 or 3 (got %s)", tostring(dim)) end
  local shape = opts.shape or (dim == 3 and "cylinder" or "rect")
  if not shapes[dim][shape] then
    local names = {}
    for k in pairs(shapes[dim]) do names[#names + 1] = k end
    table.sort(names)
    fail("lab.specimen: shape '%s' is not a %dD shape (valid: %s)", tostring(shape), dim, table.concat(names, ", "))
  end
  local size, cyl_axis, trim = shape_of(merge(opts, {shape = shape}), dim)
  -- bonds = false: a granular specimen (a sand's), left at sigma0 as the
  -- vessel held it, for the compression tests' walls to confine again
  if opts.bonds ~= nil and type(opts.bonds) ~= "boolean" then
    fail("lab.specimen: bonds must be true or false (false: a granular specimen; got %s)", tostring(opts.bonds))
  end
  local granular = opts.bonds == false
  if granular and trim then
    fail("lab.specimen: a granular specimen cannot be a %s: without bonds nothing holds a Brazilian disc together", shape)
  end
  if granular and (opts.model ~= nil or opts.gapped ~= nil) then
    fail("lab.specimen: a granular specimen has no bond model (model, gapped)")
  end
  -- a specimen of clumps: {pebbles = {...} (m:clump_template's form), scale = s | {smin, smax}}
  local grain = opts.clump
  if grain ~= nil then
    if type(grain) ~= "table" or type(grain.pebbles) ~= "table" or #grain.pebbles < 1 then
      fail("lab.specimen: clump must be {pebbles = {...}, scale = s | {smin, smax}}")
    end
    if opts.radius or opts.psd then fail("lab.specimen: a clump specimen takes scale, not %s", opts.radius and "radius" or "psd") end
  end
  local radius, sizes = genesis.sizes(opts, "lab.specimen", {0.8e-3, 1.33e-3})
  local mat = material.rock(opts.material)
  local sigma0 = opts.sigma0 or 0.1e6
  positive(sigma0, "sigma0", "specimen")
  c.warn_stress(sigma0, "sigma0", "specimen")
  -- clumps: the porosity at which the vessel has its nominal size (see below)
  local porosity = opts.porosity or (dim == 3 and 0.35 or (grain and 0.14 or 0.16))
  local seed = opts.seed or 1
  local path = opts.path or fail("lab.specimen: a path for the specimen file is required")
  check_writable(path, "path", "specimen")
  local t0 = seixo.clock()
  if not grain then check_size(size, cyl_axis, radius[2]) end -- (a clump's radii: from its template, below)

  local m = seixo.model{dim = dim}
  polling.opened(m) -- (it read a global of that name, never set: a calibration's genesis never polled)
  -- genesis is frictionless (a dense packing); the rock's friction comes back before bonding
  m:material("rock", merge(mat, {friction = 0}))
  if grain then -- the pebbles' radii, scaled: the sizes the tests and the bond gap use
    local info = m:clump_template("grain", grain.pebbles)
    local sc = type(grain.scale) == "table" and grain.scale or {grain.scale or 1, grain.scale or 1}
    local rlo, rhi = math.huge, 0
    for _, pb in ipairs(info.pebbles) do
      local r = pb.radius or pb[dim + 1]
      rlo, rhi = math.min(rlo, r), math.max(rhi, r)
    end
    radius = {rlo * sc[1], rhi * sc[2]}
  end
  if grain then check_size(size, cyl_axis, radius[2]) end
  local rmean = 0.5 * (radius[1] + radius[2])
  local kn = ball_kn(mat, rmean, dim)
  -- clumps are placed at random, at the solid fraction radius expansion
  -- starts from (0.4 in 2D, 0.25 in 3D: placement finds room easily): their
  -- vessel starts larger by the factor that brings it to the nominal size
  -- at `porosity`, and closes in about its centre
  local loose, grow = dim == 3 and 0.75 or 0.6, 1
  if grain then grow = ((1 - porosity) / (1 - loose)) ^ (1 / dim) end
  local lo, hi, centre = {}, {}, {}
  for k = 1, dim do
    lo[k], hi[k], centre[k] = 0.5 * size[k] * (1 - grow), 0.5 * size[k] * (1 + grow), 0.5 * size[k]
  end
  local v = make_vessel(m, lo, hi, kn, cyl_axis)
  local n
  if grain then
    n = m:generate{template = "grain", scale = grain.scale or 1, porosity = loose, region = v.region, seed = seed}
    say(opts, "lab.specimen: %d clumps (%d pebbles) placed at random to porosity %.3f", n, m:ball_count(), loose)
    local stages, steps = compact_clumps(m, v, centre, sigma0)
    if not stages then
      fail("lab.specimen: the clumps fill 95 %% of the vessel and still do not carry sigma0 = %g Pa at rest; "
           .. "lower sigma0 or check the template's pebbles", sigma0)
    end
    say(opts, "lab.specimen: compacted until the clumps jam: %d stages of 2 %% (%d steps)", stages, steps)
    -- then the decompression to sigma0 by the servo, still frictionless (a
    -- dense packing; P&C). A frictionless packing of clumps does not come to
    -- rest there: held at the volume where the servo brings it, its stress
    -- falls below 1e-3 sigma0 within 2000 steps as the clumps slide apart,
    -- and under the servo it creeps on (the walls at 0.83 to 0.98 sigma0, a
    -- ratio of 0.04 to 0.13 after 60,000 steps), where disks settle. So this
    -- servo stops within 10 %, and the friction comes back for the last one:
    -- with it the packing is static within a few hundred steps. (Restoring
    -- it before the decompression instead loses contacts: 2.5 per clump
    -- against 4.8 in 2D, and 0.03 more porosity.)
    steps = servo_vessel(m, v, sigma0, {max_speed = 0.5, max_steps = opts.max_steps or 30000, tol = 0.1, ratio = 0.1})
    say(opts, "lab.specimen: unloaded to about %.3g Pa, frictionless (%d steps)", sigma0, steps)
    m:material("rock", mat)
  else
    n = m:generate{method = "expand", porosity = porosity, radius = sizes.radius, psd = sizes.psd, region = v.region,
                   seed = seed, relax = false}
    say(opts, "lab.specimen: %d balls by radius expansion to porosity %.3f (%d steps), mean wall stress %.3g Pa", n,
        porosity, m:step(), v.stress())
  end

  local gap = opts.gap or 1e-3 * radius[1]
  local gen = {floaters_found = 0, floater_passes = 0, floater_growth = 0, warnings = {}}
  local floaters
  if grain then
    -- the isotropic stress, by servo-controlled walls; a small sigma0 is a
    -- tiny overlap (sigma0 d / kn), which the clumps' vibrations disturb by
    -- a few per cent: 2 % and a ratio of 1e-2 are close enough for a
    -- seating stress
    local steps, err = servo_vessel(m, v, sigma0, {max_speed = 0.5, max_steps = opts.max_steps or 30000, tol = 0.02,
                                                   ratio = 1e-2})
    say(opts, "lab.specimen: isotropic stress %.3g Pa installed within %.2f %% (%d steps)", sigma0, 100 * err, steps)
    -- floaters: clumps with fewer than dim contacts carry nothing
    local contacts = {}
    for c in m:contacts{kind = "ball-ball"} do
      if c.fn > 0 then
        local a, b = c.a.clump.id, c.b.clump.id
        contacts[a], contacts[b] = (contacts[a] or 0) + 1, (contacts[b] or 0) + 1
      end
    end
    floaters = 0
    for cl in m:clumps() do if (contacts[cl.id] or 0) < dim then floaters = floaters + 1 end end
    gen.floaters_found = floaters
  else
    floaters = genesis.steps(m, v, mat, sigma0, gap, opts, gen, function(fmt, ...) say(opts, "lab.specimen: " .. fmt, ...) end)
  end
  gen.sigma = v.stress()
  gen.vessel_porosity = 1 - solid_volume(m, grain) / v.volume()
  local _, loaded = genesis.loaded_contacts(m)
  gen.coordination = 2 * loaded / n

  local kind = opts.model or "parallel" -- "flatjoint": seixo.joints (its parameters in the material's bond table)
  if kind ~= "parallel" and kind ~= "flatjoint" then fail("lab.specimen: model must be 'parallel' or 'flatjoint'") end
  if opts.gapped ~= nil and kind ~= "flatjoint" then fail("lab.specimen: gapped is an option of flat joints") end
  if granular then
    kind = "granular"
    say(opts, "lab.specimen: granular (no bonds), %d floaters; wall stress %.4g Pa, loaded contacts per %s %.3f",
        floaters, gen.sigma, grain and "clump" or "ball", gen.coordination)
  else
    local bonds = m:bond{kind = kind, gap = gap, seed = seed, gapped = opts.gapped}
    say(opts, "lab.specimen: %d %s bonds (%.2f per %s), %d floaters; wall stress %.4g Pa, loaded contacts per "
        .. "ball %.3f", bonds, kind, 2 * bonds / n, grain and "clump" or "ball", floaters, gen.sigma, gen.coordination)
  end

  -- out of the vessel: a bonded specimen relaxes and its locked-in stresses
  -- fall; a granular one is saved as the vessel held it (it would fall
  -- apart), and a test's walls confine it before its first step
  for _, w in ipairs(v.walls) do w:remove() end
  if not granular then m:solve{ratio = 1e-4, steps = 20000} end
  if trim then -- balls (clumps: by their centroid) outside the disk go
    local c, r = trim.center, trim.radius
    if grain then -- the square the clumps jammed in, about its nominal centre
      local elo, ehi = extents(m)
      r = 0.5 * math.min(ehi[1] - elo[1], ehi[2] - elo[2])
    end
    local function outside(p) return (p[1] - c[1]) ^ 2 + (p[2] - c[2]) ^ 2 > r * r end
    local removed = 0
    if grain then
      local out = {}
      for cl in m:clumps() do if outside(cl.pos) then out[#out + 1] = cl end end
      for _, cl in ipairs(out) do cl:remove() end
      removed = #out
    else
      removed = m:remove_balls{where = function(b) return outside(b.pos) end}
    end
    m:solve{ratio = 1e-4, steps = 20000}
    say(opts, "lab.specimen: trimmed to a disk: %d %s removed, %d balls left", removed, grain and "clumps" or "balls",
        m:ball_count())
  end

  local elo, ehi = extents(m)
  local volume = 1
  for k = 1, dim do volume = volume * (ehi[k] - elo[k]) end
  if shape == "cylinder" or shape == "disc" or shape == "disk" then volume = volume * pi / 4 end
  local solid = solid_volume(m, grain)
  -- the locked-in stress and the bulk porosity, in the core of the
  -- specimen: its box (for a cylinder or a disc the box inscribed in its
  -- section; for a 2D disk a disk) less two largest radii from every side
  local margin, rmax = 2 * m:max("radius"), m:max("radius")
  local core
  if trim then
    core = {disk = {center = {0.5 * (elo[1] + ehi[1]), 0.5 * (elo[2] + ehi[2])},
                    radius = 0.5 * (ehi[1] - elo[1]) - margin}}
  else
    local clo, chi = {}, {}
    for k = 1, dim do
      local half = 0.5 * (ehi[k] - elo[k])
      if cyl_axis and k ~= cyl_axis then half = half / math.sqrt(2) end
      local mid = 0.5 * (elo[k] + ehi[k])
      clo[k], chi[k] = mid - half + margin, mid + half - margin
    end
    core = {box = {clo, chi}}
  end
  local inside = m:measure(core)
  local mean = 0
  for k = 1, dim do mean = mean + inside.stress[k][k] / dim end
  gen.locked_in, gen.locked_in_stress, gen.core_porosity = mean, inside.stress, inside.porosity
  gen.core_coordination = inside.coordination
  say(opts, "lab.specimen: %s mean stress %.4g Pa in the core (%d balls), its porosity %.4f, coordination %.3f",
      granular and "the vessel's (kept)" or "locked-in", mean, inside.balls, inside.porosity, inside.coordination)
  local spec = {
    path = path, dim = dim, shape = shape, size = size, lo = elo, hi = ehi, radius = copy(radius), psd = copy(opts.psd),
    balls = m:ball_count(), bonds = m:bond_count(), porosity = 1 - solid / volume, floaters = floaters,
    genesis = gen, rmax = rmax,
    sigma0 = sigma0, material = mat, wall_kn = kn, seed = seed, model = kind, granular = granular,
    genesis_steps = m:step(), clumps = m:clump_count(),
    clump = copy(grain),
    genesis_time = seixo.clock() - t0, diameter = opts.diameter, height = opts.height, width = opts.width,
    depth = opts.depth, thickness = opts.thickness,
  }
  -- the file holds no clock time (genesis_time: the returned table's), so
  -- that the same genesis saves the same file
  local saved = copy(spec)
  saved.genesis_time = nil
  m:vars().lab_specimen = saved
  m:save(path)
  say(opts, "lab.specimen: %d balls, %d bonds, porosity %.3f, saved to %s (%.1f s)", spec.balls, spec.bonds,
      spec.porosity, path, spec.genesis_time)
  m:close()
  return spec
end

--- The specimen saved at path (its table as lab.specimen returned it).
function specimen.open(path)
  local m = seixo.load(path)
  local spec = m:vars().lab_specimen
  m:close()
  if type(spec) ~= "table" then error("lab.open: " .. path .. " holds no lab specimen", 2) end
  spec.path = path
  return spec
end

return specimen
