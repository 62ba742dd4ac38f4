// Compiled (not run) by web/test/run.sh with TypeScript against the installed package's
// index.d.ts: an app's typical use type-checks, and a wrong option value does not.
import {
  TrisortPlayer, TrisortError, TrisortFormatError, type OpenOptions, type Clip,
} from "@trisort/player";

export async function play(canvas: HTMLCanvasElement, data: Uint8Array): Promise<number | string> {
  const options: OpenOptions = {
    canvas, data, name: "car.baked", backend: "webgl2", mode: "blend", shading: "basic", tonemap: "aces",
  };
  try {
    const player = await TrisortPlayer.open(options);
    const ms: number = player.render(0);
    const pixels: Uint8Array = await player.readFrame(0);
    const clips: Clip[] = player.clips();
    player.setClip(clips[0].name);
    const next: number = player.step(clips[0].first, -1);
    player.setVariant(null);
    const fps: number | undefined = player.fps;
    const rawWidth: number = player.raw.width();
    const total = player.frameStats(next).triangles + ms + rawWidth + pixels.length + player.frameCount + (fps ?? 0);
    player.free();
    return total;
  } catch (e) {
    if (e instanceof TrisortFormatError) {
      const code: "format" = e.code;
      return `${code}: ${e.message}`;
    }
    if (e instanceof TrisortError) return e.code;
    throw e;
  }
}

export const wrong: Partial<OpenOptions> = {
  // @ts-expect-error: not a backend the package offers
  backend: "vulkan",
};
