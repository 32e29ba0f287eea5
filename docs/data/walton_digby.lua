-- The effective moduli of a random packing of Hertz spheres against Walton
-- (1987) and Digby (1981) (docs/verification.md, "Granular elasticity:
-- Walton–Digby"; tests/lua/walton_digby.lua is its quick form in the suite):
--   build/seixo docs/data/walton_digby.lua [N] [mu] [seed] [prep] [outdir]
-- N balls (default 500; the note's tables: 1000) of radii 0.95-1.05 mm,
-- quartz-like (G = 29 GPa, nu = 0.15, 2650 kg/m^3), in a periodic cell,
-- brought by the cell's servo to 0.1, 1 and 10 MPa, with friction mu
-- (default 0.3). prep (default "frictionless"):
--   frictionless  placed overcompressed (porosity 0.34), servo to 0.1 MPa
--                 frictionless, then mu on: a dense packing
--   frictional    a gas at porosity 0.43 with mu from the start (m:generate
--                 scales the radii to 0.90-1.0 mm for it, with a warning),
--                 its radii grown until it carries 0.03 MPa: a loose packing
-- At each pressure: the coordination Z (every force-carrying contact, and
-- without rattlers, balls of fewer than 4), the porosity, then small strain
-- increments with the cell held and the balls relaxed (ratio 1e-6): the
-- bulk modulus K (isotropic compression, then the unloading back) and the
-- shear modulus G (pure shear xx/yy, and reversed); Walton-Digby's K,
-- G rough (no slip) and G smooth (frictionless) with the measured Z and
-- porosity; the affine (Voigt) moduli of the actual contact network. Ends
-- with a CSV table and the exponents d ln K / d ln p. With outdir, the
-- state at each pressure is saved there (outdir/wd_N..._p....h5).
-- Seed 1 at 1,000 balls gives the note's tables to the last digit: 111 s
-- of CPU frictionless (most of it in the first servo stage, at max_rate
-- 2e-5 strain a step; the suite's test takes 1e-4 and local damping 0.5),
-- 34 s frictional.
local N = tonumber(arg[1]) or 500
local MU = tonumber(arg[2]) or 0.3
local SEED = tonumber(arg[3]) or 1
local PREP = arg[4] or "frictionless"
local OUT = arg[5]
assert(PREP == "frictionless" or PREP == "frictional", "prep is frictionless or frictional")
local PRES = {1e5, 1e6, 1e7}
local G, NU, RHO = 29e9, 0.15, 2650
local R0 = 1e-3
local t0 = seixo.clock()
local m = seixo.model{dim = 3}
local function mat(mu)
  m:material("q", {model = "hertz", shear_modulus = G, poisson = NU, density = RHO, friction = mu, damping = 0.7})
end
mat(0)
-- the cell for a solid fraction of 0.66; the balls fill it at the porosity
-- of the preparation (0.34 overcompressed: the expansion jams it)
local vb = N * 4 / 3 * math.pi * R0 ^ 3
local L = (vb / 0.66) ^ (1 / 3)
m:periodic{min = {0, 0, 0}, max = {L, L, L}}
local n = m:generate{method = "expand", porosity = PREP == "frictionless" and 0.34 or 0.43, count = N,
                     radius = {0.95 * R0, 1.05 * R0}, region = {box = {{0, 0, 0}, {L, L, L}}}, seed = SEED,
                     relax = PREP ~= "frictionless" and {steps = 20000} or false}
local function p_of(s) return (s[1][1] + s[2][2] + s[3][3]) / 3 end
local function log(fmt, ...)
  io.write(string.format("[%6.1fs step %7d] ", seixo.clock() - t0, m:step()), string.format(fmt, ...), "\n")
  io.flush()
end
log("generated %d balls, L = %.4g m, p = %.4g Pa, dt %.3g", n, L, p_of(m:cell_stress()), m:timestep())

-- the servo on every normal component to p; cycles until within tol and the
-- ratio below rtol
local function servo_to(p, tol, rtol, maxsteps, alpha)
  m:cell_control{xx = {stress = p}, yy = {stress = p}, zz = {stress = p}, alpha = alpha or 0.2,
                 max_rate = 2e-5 / m:timestep()}
  local start = m:step()
  local err, r
  repeat
    m:cycle(500)
    local st = m:cell_stress()
    err = 0
    for k = 1, 3 do err = math.max(err, math.abs(st[k][k] / p - 1)) end
    r = m:ratio()
  until (err < tol and r < rtol) or m:step() - start > maxsteps
  return err, r
end
-- the cell held still, the balls relaxed
local function hold_relax(rtol, maxsteps)
  m:cell_control{xx = {rate = 0}, yy = {rate = 0}, zz = {rate = 0}}
  local start = m:step()
  repeat m:cycle(200) until m:ratio() < rtol or m:step() - start > maxsteps
  return m:ratio()
end
local function rates(rx, ry, rz)
  m:cell_control{xx = {rate = rx}, yy = {rate = ry}, zz = {rate = rz}}
end
-- Z (force-carrying contacts per ball; and over the balls of 4 or more
-- contacts), the rattlers, the porosity, the mean overlap / R
local function fabric()
  local cnt = {}
  local nc, ov = 0, 0
  for c in m:contacts{kind = "ball-ball"} do
    if c.fn > 0 then
      nc = nc + 1
      ov = ov + c.overlap
      cnt[c.a.id] = (cnt[c.a.id] or 0) + 1
      cnt[c.b.id] = (cnt[c.b.id] or 0) + 1
    end
  end
  local nb = m:ball_count()
  local nr, cr = 0, 0
  for b in m:balls() do
    local k = cnt[b.id] or 0
    if k < 4 then nr = nr + 1 else cr = cr + k end
  end
  local cell = m:periodic()
  local V = cell.size[1] * cell.size[2] * cell.size[3]
  local phi = 1 - m:sum("volume") / V
  return 2 * nc / nb, cr / (nb - nr), nr, phi, ov / nc / R0
end
-- a strain increment (per axis, extension positive) over nsteps, then the
-- cell held and the balls relaxed
local function increment(ex, ey, ez, nsteps, rtol)
  local s0 = m:cell_stress()
  local L0 = m:periodic().size
  local T = nsteps * m:timestep()
  rates(ex / T, ey / T, ez / T)
  m:cycle(nsteps)
  local r = hold_relax(rtol, 200000)
  local s1 = m:cell_stress()
  local L1 = m:periodic().size
  local e = {L1[1] / L0[1] - 1, L1[2] / L0[2] - 1, L1[3] / L0[3] - 1}
  return s0, s1, e, r
end
-- the affine (Voigt) moduli of the actual contact network: K = sum kn l^2 /
-- (9V), G = sum l^2 (2 kn + 3 ks) / (30 V) (an isotropic fabric), kn the
-- Hertz tangent stiffness 3/2 Fn/overlap, ks the contact's (Mindlin) shear
-- stiffness; and G with ks = 0
local function affine()
  local cell = m:periodic()
  local V = cell.size[1] * cell.size[2] * cell.size[3]
  local sk, sg, sg0 = 0, 0, 0
  for c in m:contacts{kind = "ball-ball"} do
    if c.fn > 0 and c.overlap > 0 then
      local kn = 1.5 * c.fn / c.overlap
      local l = c.a.radius + c.b.radius - c.overlap
      sk = sk + kn * l * l
      sg = sg + l * l * (2 * kn + 3 * c.ks)
      sg0 = sg0 + l * l * 2 * kn
    end
  end
  return sk / (9 * V), sg / (30 * V), sg0 / (30 * V)
end
-- Walton (1987) / Digby (1981): identical Hertz spheres under an isotropic
-- pressure p, Z contacts per ball, porosity phi
local function wd(Z, phi, p)
  local lam = 2 * G * NU / (1 - 2 * NU)
  local B = (1 / (4 * math.pi)) * (1 / G + 1 / (G + lam))
  local A = (1 / (4 * math.pi)) * (1 / G - 1 / (G + lam))
  local K = (1 / 6) * (3 * (1 - phi) ^ 2 * Z ^ 2 * p / (math.pi ^ 4 * B ^ 2)) ^ (1 / 3)
  local Grough = 3 / 5 * K * (5 * B + A) / (2 * B + A)
  local Gsmooth = 3 / 5 * K
  return K, Grough, Gsmooth
end

local err, r
if PREP == "frictionless" then
  -- frictionless to the first pressure, then friction on
  err, r = servo_to(PRES[1], 0.01, 1e-3, 150000, 0.2)
  log("frictionless servo to %.3g: err %.3g ratio %.3g", PRES[1], err, r)
  mat(MU)
else
  -- friction on from the gas: every radius grown by 1e-4 each 200 steps
  -- until the pressure reaches 0.3 of the first target (the cell held still)
  mat(MU)
  m:cell_control{xx = {rate = 0}, yy = {rate = 0}, zz = {rate = 0}}
  local stages = 0
  while p_of(m:cell_stress()) < 0.3 * PRES[1] and stages < 2000 do
    for b in m:balls() do b.radius = b.radius * (1 + 1e-4) end
    m:cycle(200)
    stages = stages + 1
  end
  log("frictional radius growth: %d stages, p = %.4g", stages, p_of(m:cell_stress()))
end
local results = {}
for _, p in ipairs(PRES) do
  servo_to(p, 0.002, 1e-4, 200000, 0.2)
  r = hold_relax(1e-6, 200000)
  local s = m:cell_stress()
  local p0 = p_of(s)
  local Z, Zr, nr, phi, ovr = fabric()
  log("p target %.3g: p %.5g (xx %.4g yy %.4g zz %.4g) ratio %.2g; Z %.3f (no rattlers %.3f, %d rattlers) porosity %.4f, mean overlap/R %.3g",
      p, p0, s[1][1], s[2][2], s[3][3], r, Z, Zr, nr, phi, ovr)
  if OUT then m:save(string.format("%s/wd_N%d_mu%g_s%d_%s_p%g.h5", OUT, N, MU, SEED, PREP, p)) end
  -- about 3 % of p
  local eps = 5e-6 * (p / 1e5) ^ (2 / 3)
  -- bulk: isotropic compression eps per axis, then the same back
  local s0, s1, e, rr = increment(-eps, -eps, -eps, 2000, 1e-6)
  local dp = p_of(s1) - p_of(s0)
  local K = dp / -(e[1] + e[2] + e[3])
  log("  K: dev %.4g, dp %.4g Pa (%.2f%% of p), K = %.4g Pa (ratio %.2g)", -(e[1] + e[2] + e[3]), dp, 100 * dp / p0, K, rr)
  local s2, s3, e2 = increment(eps, eps, eps, 2000, 1e-6)
  local Ku = (p_of(s2) - p_of(s3)) / (e2[1] + e2[2] + e2[3])
  log("  K unloading: %.4g Pa", Ku)
  -- shear: pure shear exx = +eps, eyy = -eps; with compression-positive
  -- stress and extension-positive strain d(syy - sxx) = 2 G (d exx - d eyy)
  local g0, g1, ge, rg = increment(eps, -eps, 0, 2000, 1e-6)
  local dq = (g1[2][2] - g1[1][1]) - (g0[2][2] - g0[1][1])
  local Gm = dq / (2 * (ge[1] - ge[2]))
  log("  G (pure shear): dq %.4g Pa, G = %.4g Pa (ratio %.2g)", dq, Gm, rg)
  local g2, g3, ge2 = increment(-eps, eps, 0, 2000, 1e-6)
  local dq2 = (g3[2][2] - g3[1][1]) - (g2[2][2] - g2[1][1])
  local Gm2 = dq2 / (2 * (ge2[1] - ge2[2]))
  log("  G (reverse): G = %.4g Pa", Gm2)
  local pm = p0 + 0.5 * dp
  local Kwd, Gr, Gs = wd(Z, phi, pm)
  local Kwd2 = wd(Zr, phi, pm)
  log("  Walton-Digby at p %.4g, Z %.3f, phi_solid %.4f: K %.4g (DEM/WD %.3f); G rough %.4g (DEM/WD %.3f), smooth %.4g (DEM/WD %.3f); with Z no rattlers K %.4g (DEM/WD %.3f)",
      pm, Z, 1 - phi, Kwd, K / Kwd, Gr, Gm / Gr, Gs, Gm / Gs, Kwd2, K / Kwd2)
  local Ka, Ga, Ga0 = affine()
  log("  affine (Voigt) of the contact network: K %.4g (DEM/affine %.3f, affine/WD %.3f); G rough %.4g (DEM/affine %.3f, affine/WD %.3f), G smooth %.4g",
      Ka, K / Ka, Ka / Kwd, Ga, Gm / Ga, Ga / Gr, Ga0)
  results[#results + 1] = {p = pm, Z = Z, Zr = Zr, phi = phi, K = K, Ku = Ku, G = Gm, G2 = Gm2, Kwd = Kwd, Gr = Gr, Gs = Gs}
end
print("p,Z,Z_norattlers,porosity,K,K_unload,G,G_rev,K_WD,G_WD_rough,G_WD_smooth")
for _, x in ipairs(results) do
  print(string.format("%.5g,%.4f,%.4f,%.5f,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g", x.p, x.Z, x.Zr, x.phi, x.K, x.Ku, x.G, x.G2,
                      x.Kwd, x.Gr, x.Gs))
end
for i = 2, #results do
  local a, b = results[i - 1], results[i]
  print(string.format("exponent d ln K / d ln p between %.3g and %.3g: %.3f (WD at fixed Z, phi: 1/3)", a.p, b.p,
                      math.log(b.K / a.K) / math.log(b.p / a.p)))
end
