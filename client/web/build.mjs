// Builds the page into one folder the server can serve: index.html, style.css, app.js (src/ and its npm
// dependencies bundled by esbuild, so nothing is fetched from the internet at run time) and samples/
// (a few test meshes with samples.json).
//
//   node build.mjs --out DIR [--samples-dir DIR]
//
// CMake runs this (target balloon_web) with --out ${CMAKE_BINARY_DIR}/client/web/dist.
import { build } from 'esbuild';
import { copyFileSync, mkdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parse_obj } from './src/obj_parser.js';
import { parse_off } from './src/off_parser.js';

const HERE = dirname(fileURLToPath(import.meta.url));

/** The samples offered on the page: file in tests/data/meshes and the name shown. */
const SAMPLES = [
  { file: 'icosphere_812.off', name: 'Sphere' },
  { file: 'cube_866.off', name: 'Cube' },
  { file: 'stanford_bunny_1839.obj', name: 'Stanford bunny' },
  { file: 'spot.obj', name: 'Spot the cow' },
];

function parse_arguments(argv) {
  const options = { out: join(HERE, 'dist'), samples_dir: resolve(HERE, '../../tests/data/meshes') };
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === '--out') options.out = resolve(argv[++i]);
    else if (argv[i] === '--samples-dir') options.samples_dir = resolve(argv[++i]);
    else {
      console.error(`build.mjs: unknown argument '${argv[i]}' (use --out DIR [--samples-dir DIR])`);
      process.exit(2);
    }
  }
  return options;
}

async function main() {
  const options = parse_arguments(process.argv.slice(2));
  rmSync(options.out, { recursive: true, force: true });
  mkdirSync(join(options.out, 'samples'), { recursive: true });

  await build({
    entryPoints: [join(HERE, 'src/main.js')],
    bundle: true,
    format: 'esm',
    target: ['es2020'],
    minify: true,
    sourcemap: 'linked',
    legalComments: 'linked',
    outfile: join(options.out, 'app.js'),
    logLevel: 'warning',
  });
  for (const file of ['index.html', 'style.css']) copyFileSync(join(HERE, file), join(options.out, file));

  const listed = [];
  for (const sample of SAMPLES) {
    const source = join(options.samples_dir, sample.file);
    const text = readFileSync(source, 'utf8');
    const is_obj = sample.file.endsWith('.obj');
    // Parsing here proves each sample reads in the page's own parsers, and gives the vertex count.
    const mesh = is_obj ? parse_obj(text) : parse_off(text);
    copyFileSync(source, join(options.out, 'samples', sample.file));
    listed.push({
      name: sample.name,
      file: sample.file,
      format: is_obj ? 'MESH_FORMAT_OBJ' : 'MESH_FORMAT_OFF',
      vertices: mesh.positions.length / 3,
    });
  }
  writeFileSync(join(options.out, 'samples', 'samples.json'), JSON.stringify(listed, null, 2) + '\n');
  console.log(`balloon_web: page written to ${options.out}`);
}

main().catch((error) => {
  console.error(`build.mjs: ${error.message}`);
  process.exit(1);
});
